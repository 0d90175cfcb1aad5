// pinmech's compiled core, the one engine: the closure rows, Newton (`close`, `correct`),
// the predictor-corrector continuation with every assembly rule (trust region, tangent
// turn, signature, change points, the curve on a joint parameter through folds, landing)
// and the rate solves, in C++ on Pinocchio, on the user's own pin.Model (taken by
// reference from Python: model_ref.cpp). Pose (`close`, `rates_at`, `follow_path`), range
// (`follow`) and batch (BatchSolver's calls) are its modes. Python (pinmech/solve/) orders
// the calls and names what the core reports (a status and the numbers): where the range
// mode meets a change point, a fold, a pose worse conditioned than max_condition or
// overflowing rates, it stops and the pose-by-pose `follow_path` names and notes it.
// pinmech/solve/core.py builds it from a LoopSolver; tests/test_core.py checks it against
// closed forms, SVDs and finite differences.
//
// One translation unit per concern, so that a change recompiles little and the compile
// stays within modest memory: condition.cpp (condition numbers), closure.cpp (the model,
// closure rows, their Jacobians and drift, assembly blocks), continuation.cpp (corrector,
// predictor-corrector steps, sweeps), pivot.cpp (Newton with least squares, the whole
// path follow: folds, landing, change points), rates.cpp (rate problems, frames along a sweep),
// model_ref.cpp (the pin.Model from Python), module.cpp (the Python bindings). Pinocchio's
// algorithms come compiled from libpinocchio_default (PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION),
// the library the installed `pin` loads: the same version, pinned in pyproject.toml.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <pinocchio/multibody.hpp>

#include <cmath>
#include <complex>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "buffer.hpp"
#include "condition.hpp"
#include "square_solve.hpp"

namespace pinmech {

namespace nb = nanobind;
namespace pin = pinocchio;

using Eigen::Index;
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;
// At most six rows of six columns (a cut's closure rows), sized at run time: products with
// a 6-vector are unrolled, where a dynamic matrix would go through Eigen's general kernel.
using Rows6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, 6, 6>;

// The constants of solve_loops.py and continuation.py (tests/test_core.py reads them back).
constexpr double DEFAULT_TOL = 1e-13;
constexpr double POLISH = 1e-15;
constexpr double MAX_NEWTON_STEP = 1.0;  // solve_loops.MAX_STEP
constexpr double MAX_STEP = 0.25;        // continuation.MAX_STEP
constexpr double TRUST = 0.25;
constexpr double MAX_TURN = 30.0 * M_PI / 180.0;
constexpr double PIVOT_BELOW = 1e-4;
constexpr int CORRECTOR_ITERATIONS = 8;
constexpr double SINGULAR_NODE = 1e10;
// A closed pose is a root of one branch, its tangent that branch's, only outside Newton's
// reach of a singular pose (Kantorovich: residual x curvature / sigma_min^2 small; the
// dimensionless closure's curvature is of order 1). The tangent is then good to about that
// ratio (rad), against the 3 deg a change point's turn may take. A corrector that lands on
// a change point (a crossing of two branches) stalls where the ratio is of order 1 (0.5 to
// 1.5 measured on a parallelogram four-bar), with a tangent between the branches' from
// which the next step can take either: such a landing is refused, as a singular pose.
constexpr double NEWTON_REACH = 1e-3;
inline bool within_reach_of_singular(double residual, double sigma_min) {
  return !(residual <= NEWTON_REACH * sigma_min * sigma_min);
}
constexpr int LINE_SEARCH_HALVINGS = 30;

// The constants of the pivot-parametrized curve through folds (pivot.cpp; continuation.py's).
constexpr double BIFURCATION_STEP = 1e-3;
constexpr double FOLD_TOL = 1e-12;
constexpr double LAND_TOL = 1e-12;
constexpr long MAX_PIVOT_STEPS = 20000;
constexpr int LAND_ITERATIONS = 50;

// Steps between two looks at Python's signal handlers in a long loop run without the GIL.
constexpr long SIGNAL_EVERY = 4096;
// Python's signal handlers, from a loop that released the GIL (continuation.cpp).
void check_signals();

enum CutType { REVOLUTE, PRISMATIC, SPHERICAL_CUT, FIXED };

// Why a sweep stopped before its last pose (the pose-by-pose follow then takes that pose).
enum Stop { DONE = 0, NEEDS_PIVOT = 1, SIGNATURE_CHANGED = 2, CONDITION = 3, NOT_FINITE = 4 };

// The pin.Model inside a Python object made by the installed `pin` (model_ref.cpp), or
// nullptr where the object is no pin.Model.
pin::Model* borrow_model(PyObject* obj);
// The pin.Data inside a Python object made by the installed `pin`, or nullptr.
pin::Data* borrow_data(PyObject* obj);

// ------------------------------------------------------------ kinematics.cpp
// A row per frame, then per joint: position (3) [m], rotation (9, row-major), velocity
// (3) [m/s], angular velocity (3) [rad/s], classical acceleration (3) [m/s^2], angular
// acceleration (3) [rad/s^2], world axes (LOCAL_WORLD_ALIGNED).
constexpr int KINEMATICS_COLUMNS = 24;
// Numbers `Core::rates` gives a pose (rates.cpp).
constexpr int RATE_NUMBERS = 9;
// Pinocchio's forward kinematics at (q, v, a) in `data`, then a row per frame and joint
// asked written at `out` (ids checked by the caller).
void pose_kinematics(const pin::Model& model, pin::Data& data, const double* q, const double* v, const double* a,
                     const int* frames, Index nframes, const int* joints, Index njoints, double* out);
// One pose on the user's model and data (arrays: buffer.hpp): `out`, float64 of
// (frames + joints) * KINEMATICS_COLUMNS items, gets the rows.
void frames_at(nb::handle model, nb::handle data, nb::handle q, nb::handle v, nb::handle a, nb::handle frames,
               nb::handle joints, nb::handle out);
// N poses (Q, V, A: N rows): `out`, N * frames * KINEMATICS_COLUMNS items, pose by pose.
void frames_along(nb::handle model, nb::handle data, nb::handle Q, nb::handle V, nb::handle A, nb::handle frames,
                  nb::handle out);

// A column of data.J (Pinocchio's joint Jacobians, nvExtended columns: a mimic joint has
// its own, already times its scaling) and the velocity column it adds to (a mimic
// joint's is its leader's).
struct JointColumn {
  Index extended, v;
};

// A frame's world motion (LOCAL_WORLD_ALIGNED): origin x [m], rotation R, origin velocity v
// [m/s], angular velocity w [rad/s], origin classical acceleration acc [m/s^2], angular
// acceleration alpha [rad/s^2]. S: double, or std::complex<double> for a complex step.
template <typename S>
struct FrameMotion {
  Eigen::Matrix<S, 3, 1> x, v, w, acc, alpha;
  Eigen::Matrix<S, 3, 3> R;
};

// a x b, analytic in complex entries (Eigen's cross conjugates them).
template <typename S>
Eigen::Matrix<S, 3, 1> cross3(const Eigen::Matrix<S, 3, 1>& a, const Eigen::Matrix<S, 3, 1>& b) {
  return Eigen::Matrix<S, 3, 1>(a(1) * b(2) - a(2) * b(1), a(2) * b(0) - a(0) * b(2), a(0) * b(1) - a(1) * b(0));
}

// The motion of a cut's child frame C relative to its parent P, in P's axes: the 6-vector
// its velocity rows select from, (r_dot, w) = (R_P^T (v_C - v_P - w_P x delta), R_P^T (w_C - w_P)),
// delta = x_C - x_P [m/s, rad/s].
template <typename S>
Eigen::Matrix<S, 6, 1> relative_velocity6(const FrameMotion<S>& P, const FrameMotion<S>& C) {
  Eigen::Matrix<S, 6, 1> e;
  e.template head<3>() = P.R.transpose() * (C.v - P.v - cross3<S>(P.w, C.x - P.x));
  e.template tail<3>() = P.R.transpose() * (C.w - P.w);
  return e;
}

// Its time derivative, the 6-vector the acceleration rows select from [m/s^2, rad/s^2]:
// R_P^T (d_dot - w_P x d), d = v_C - v_P - w_P x delta, d_dot = acc_C - acc_P - alpha_P x delta
// - w_P x (v_C - v_P); and R_P^T (alpha_C - alpha_P - w_P x (w_C - w_P)). At zero joint
// accelerations, the drift.
template <typename S>
Eigen::Matrix<S, 6, 1> relative_acceleration6(const FrameMotion<S>& P, const FrameMotion<S>& C) {
  using V3 = Eigen::Matrix<S, 3, 1>;
  const V3 delta = C.x - P.x, dv = C.v - P.v;
  const V3 d = dv - cross3<S>(P.w, delta);
  const V3 d_dot = C.acc - P.acc - cross3<S>(P.alpha, delta) - cross3<S>(P.w, dv);
  Eigen::Matrix<S, 6, 1> e;
  e.template head<3>() = P.R.transpose() * (d_dot - cross3<S>(P.w, d));
  e.template tail<3>() = P.R.transpose() * (C.alpha - P.alpha - cross3<S>(P.w, V3(C.w - P.w)));
  return e;
}

// The change of a cut's velocity (order 1) or acceleration (order 2) rows, rows6 times the
// 6-vector above, along a change of both frames' motions (closure.cpp). P, C: (8, 3), rows
// x, v, w, acc, alpha, then R's three rows; dP, dC: (6, 3), rows dx, dv, dw, dacc, dalpha
// and dtheta, the frame's turn (dR = [dtheta]x R), all in world axes.
VectorXd cut_rows_change(const Eigen::Ref<const RowMatrix>& rows6, int order, const Eigen::Ref<const RowMatrix>& P,
                         const Eigen::Ref<const RowMatrix>& C, const Eigen::Ref<const RowMatrix>& dP,
                         const Eigen::Ref<const RowMatrix>& dC);

struct Cut {
  int type;
  pin::FrameIndex parent, child;
  Vector3d axis, child_axis;
  Rows6 rows6;  // (k, 6): basis @ selection @ diag(scale), as Closure._rows6
  Rows6 full;   // (n_sel, 6): selection @ diag(scale), every selected row
  Index offset;    // first row in the stacked residual
  bool ground;     // P is a frame of the ground: no Jacobian, velocity or acceleration
  // The velocity columns that move C relative to P: joints supporting C and not P, and
  // joints supporting P and not C. A joint supporting both moves P and C together, so its
  // column of the relative Jacobian is zero (exactly, where the full difference would
  // leave rounding): a cut costs the joints of its own loop, not the depth of the tree.
  std::vector<JointColumn> child_cols, parent_cols;
  // Velocity columns several data.J columns add to (mimic joints): zeroed, then summed.
  bool shared_columns = false;
  // The distinct velocity columns of child_cols and parent_cols, ascending: the only
  // columns of the cut's rows of J_ that are not exactly zero.
  std::vector<Index> columns;
};

// A piece of J_dep that is not structurally zero: the `rows` rows from `offset` of a cut,
// in J_dep's column `dep`, which is J_'s velocity column `v`.
struct ColumnBlock {
  Index offset, rows, v, dep;
};

struct Node {
  double p = 0.0;
  VectorXd q, d1, d2;
  std::vector<int> signs;
  double condition = 1.0, sigma_min = 1.0, velocity_residual = 0.0, acceleration_residual = 0.0, residual = 0.0;
};

// A point of the solution curve in (q, p), followed with one dependent joint's coordinate
// (`pivot`, a velocity index) as its parameter: its unit tangent (dq in velocity space,
// then dp in radians or sizes), oriented along the travel, and s, the pivot's displacement
// since the last change of pivot (pivot.cpp).
struct CurvePoint {
  double p = 0.0, s = 0.0;
  VectorXd q, tangent;
  int pivot = -1;
  double dp() const { return tangent(tangent.size() - 1); }
};

// A straight driver path x(p) = x0 + p d (continuation.Path), with what its curve needs.
struct PathSpec {
  VectorXd x0, d, d_hat;  // d_hat = d / unit: drivers' motion per radian or size along the path
  double unit = 1.0;
  bool through_folds = false;
  std::vector<int> scalar;  // dependent velocity indices of one-coordinate joints (pivots)
  double ds = 1e-3;         // the curve's adaptive pivot step
};

// A path along drivers x(p) = x0 + p d, `unit` the drivers' size (radians or lengths) a unit of p.
inline PathSpec make_path(const VectorXd& x0, const VectorXd& d, double unit, bool through_folds,
                          const std::vector<int>& scalar) {
  PathSpec path;
  path.x0 = x0;
  path.d = d;
  path.unit = unit;
  path.d_hat = d / unit;
  path.through_folds = through_folds;
  path.scalar = scalar;
  return path;
}

// The node a path starts from: its p, pose, path derivatives, signature and condition number.
inline Node start_node(double p, const VectorXd& q, const VectorXd& d1, const VectorXd& d2,
                       const std::vector<int>& signs, double condition) {
  Node node;
  node.p = p;
  node.q = q;
  node.d1 = d1;
  node.d2 = d2;
  node.signs = signs;
  node.condition = condition;
  return node;
}

// How Path.follow ended (pivot.cpp). Python builds the named error from it.
// PATH_REFUSED: a step left uncertified (the dial below) was refused; the range mode then
// follows again from its last certified pose, certifying every pose.
enum PathStatus { PATH_DONE = 0, PATH_STUCK = 1, PATH_FOLD = 2, PATH_SINGULAR = 3, PATH_REFUSED = 4 };

// The certification dial (Core::certify_every): which poses of a range get the exact
// condition number. Every pose gets its residuals (closure, velocity, acceleration), the
// trust region, the tangent's turn limit and its assembly signature (a sign a block: where
// it changes between certified poses, the range is followed again, every pose certified).
constexpr int CERTIFY_EVERY_POSE = 1;  // k >= 2: every k-th pose and a range's last
constexpr int CERTIFY_ENDS = 0;        // a range's last pose (its first is certified already)
constexpr int CERTIFY_NONE = -1;       // no pose: residual tolerances only
// Whether the pose `i` of `n` is certified at level `every`.
inline bool certify_due(int every, long i, long n) {
  if (every == CERTIFY_EVERY_POSE) return true;
  if (every == CERTIFY_NONE) return false;
  return i == n - 1 || (every >= 2 && (i + 1) % every == 0);
}
// Why a path is stuck (continuation.py words them): 1-5 the last failed step's reason
// (Core::step's codes; 5 the assembly changed: signs_a -> signs_b), then
enum StuckWhy { NO_PIVOT = 6, ANOTHER_ASSEMBLY_NEAR = 7, TARGET_NOT_CLOSED = 8, TARGET_ON_ANOTHER = 9 };

struct PathResult {
  int status = PATH_DONE, why = 0;
  Node node;  // reached (DONE); where it is stuck (STUCK, FOLD); the singular pose (SINGULAR)
  double p_target = 0.0, fold = NAN;
  long steps = 0, iterations = 0;
  std::vector<double> change_points, folds;  // path parameters passed
  std::vector<int> signs_a, signs_b;
};

// A generated kernel loaded into a core (kernel.cpp): Pinocchio's kinematic passes
// specialised to the model, C functions of x = [q | v | a | joint placements] writing y
// (pinmech/kernelgen/generator.cpp documents the layout).
struct Kernel {
  using Pass = void (*)(const double*, double*);
  void* handle = nullptr;  // dlopen's
  Pass placements = nullptr, jacobians = nullptr, motion = nullptr;
  VectorXd x, y;
  std::string path;
  pin::Model::JointModelVector joints;  // the joints it was generated for (types, axes, pitches...)
  Kernel() = default;
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;
  ~Kernel();
};

class Core {
 public:
  // `model`: a pin.Model, kept alive and read at every call (a joint or frame placement
  // changed in it is used at the next call); `frame_ids`: its frames the core may name by
  // their index in this list (cuts' frames, task frames).
  Core(nb::object model, const std::vector<int>& frame_ids, const std::vector<int>& cut_types,
       const std::vector<int>& cut_parent, const std::vector<int>& cut_child,
       const Eigen::Ref<const RowMatrix>& cut_axes, const Eigen::Ref<const RowMatrix>& cut_child_axes,
       const std::vector<MatrixXd>& rows6, const std::vector<MatrixXd>& full, const std::vector<int>& drv_v,
       const std::vector<int>& dep_v, const std::vector<int>& drv_q, const std::vector<int>& drv_continuous,
       const VectorXd& v_scale, const std::vector<std::vector<int>>& block_rows,
       const std::vector<std::vector<int>>& block_cols, double tol);

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }
  std::vector<int> idx_q() const { return std::vector<int>(model_.idx_qs.begin() + 1, model_.idx_qs.end()); }
  std::vector<int> idx_v() const { return std::vector<int>(model_.idx_vs.begin() + 1, model_.idx_vs.end()); }
  nb::object model() const { return model_object_; }
  // Whether the model still has the joints and frames this core was built on (a
  // placement may have changed, not the tree); every entry point checks it.
  bool same_structure() const;

  // ------------------------------------------------------------ closure rows (closure.cpp)
  VectorXd residual(const VectorXd& q);
  void residual_into(const VectorXd& q, VectorXd& r, bool jacobians = false);
  double full_residual() const;
  MatrixXd jacobian(bool newton);
  void jacobian_into(bool newton);
  void rows_times(const VectorXd& x, VectorXd& out) const;  // J_ x by each cut's own columns
  VectorXd drift(const VectorXd& q, const VectorXd& v);
  void drift_into(const VectorXd& q, const VectorXd& v, VectorXd& out);
  std::vector<int> signs(const MatrixXd& J_dep);
  void signs_into(const MatrixXd& J_dep, std::vector<int>& out);
  // Each cut's pose error (cuts, 6) at q, before selection and scale: C's position in P
  // [m], its orientation error [rad, or the sine of the axes' angle for a revolute cut].
  RowMatrix errors6(const VectorXd& q);
  // (rows, 3) at the q of the last residual: the rows' change per world translation [m] of
  // the child cut frame (minus it, of the parent's), orientation rows unchanged.
  RowMatrix translation_rows() const;

  // ------------------------------------------------------------ continuation.cpp
  bool correct(VectorXd& q, const VectorXd& drivers, int max_iterations, double& residual_left);
  // a_drv: the drivers' accelerations (zero where null: path derivatives)
  void node_at(Node& node, const VectorXd& d, const VectorXd* a_drv = nullptr);
  int step(const Node& from, double p, const VectorXd& x0, const VectorXd& d, double unit, Node& out, bool& change);
  nb::tuple follow(double p0, const VectorXd& q0, const VectorXd& d1, const VectorXd& d2, const std::vector<int>& signs0,
                   double condition0, const VectorXd& x0, const VectorXd& d, double unit, const VectorXd& targets,
                   double max_condition);
  nb::tuple node(const VectorXd& q, const VectorXd& d);

  // ------------------------------------------------------------ pivot.cpp
  // LoopSolver.close and correct(strict=False): Newton steps kept where they lower the
  // residual, else a minimum-norm least-squares step halved until it does; the polish.
  bool close(VectorXd& q, const VectorXd& drivers, int max_iterations, bool polish_within, double& residual_left);
  // LoopSolver._rates: v, a at a closed q from the drivers' v and a, with the accuracy.
  nb::tuple rates_at(const VectorXd& q, const VectorXd& v_drv, const VectorXd& a_drv);
  nb::tuple close_py(VectorXd q, const VectorXd& drivers, int max_iterations, bool polish_within);
  // Path.follow from a node to p_target: regular steps, and where they shrink below
  // PIVOT_BELOW the curve with a dependent joint as parameter (folds, landing).
  void follow_path(Node& node, double p_target, PathSpec& path, PathResult& out);  // node: worked on in place
  nb::tuple follow_path_py(double p0, const VectorXd& q0, const VectorXd& d1, const VectorXd& d2,
                           const std::vector<int>& signs0, double condition0, const VectorXd& x0, const VectorXd& d,
                           double unit, double p_target, bool through_folds, const std::vector<int>& scalar);

  // ------------------------------------------------------------ rates.cpp
  // The task rows RateSolver.solve stacks under the closure rows: frames (indices into
  // this core's frames), the components (0-5: x y z wx wy wz) of each, and whether each is
  // read in the frame's own axes.
  void set_task(const std::vector<int>& task_frames, const std::vector<std::vector<int>>& task_rows,
                const std::vector<int>& task_local);
  // The stacked Jacobian (closure rows, then task rows) at q, not made dimensionless.
  MatrixXd stacked_jacobian(const Eigen::Ref<const VectorXd>& q);
  // How the rate task is solved: the row and column scales that make it dimensionless,
  // the method asked (0 exact, 1 least squares, 2 damped), the damping, max_condition.
  void set_rate_options(const VectorXd& row_scale, const VectorXd& v_scale, int method, double damping,
                        double max_condition);
  // Columns of `rates`' answer a pose: v, a (nv each), RATE_NUMBERS numbers, the achieved
  // task rows' velocities and accelerations.
  int rate_columns() const { return 2 * model_.nv + RATE_NUMBERS + 2 * int(task_size_); }
  // RateSolver.solve at every row of Q (n rows of nq, buffer.hpp), the task's values
  // x_dot, x_ddot; `out` (n * rate_columns() float64) gets the answers (see rates.cpp).
  void rates(nb::handle Q, nb::handle x_dot, nb::handle x_ddot, int structural_rank, nb::handle out);
  RowMatrix pinocchio_passes(const Eigen::Ref<const RowMatrix>& Q, const Eigen::Ref<const RowMatrix>& V,
                             int jacobians);

  double tol() const { return tol_; }
  void set_tol(double tol) { tol_ = tol; }
  // The certification dial of the range and rate modes (CERTIFY_* above); the pose mode
  // (close, node, rates_at, follow_path) certifies every pose whatever it is.
  int certify_every() const { return certify_every_; }
  void set_certify_every(int every);
  int iterations() const { return iterations_; }
  // Diagonal blocks the dependent solves go through (0: the whole matrix at once).
  int solve_blocks() const { return int(square_.blocks()); }
  double moved() const { return moved_; }
  // The dependent velocity indices of one-coordinate joints, the pivots a path's curve
  // may take through a fold (LoopSolver.dep_is_scalar), for the range mode's `follow`.
  void set_pivots(const std::vector<int>& scalar);
  // Throws (a ValueError in Python) where the model's joints or frames changed.
  void check_structure() const;

  // ------------------------------------------------------------ kernel.cpp
  // The kinematic passes from the generated kernel at `path` (checked: made for this
  // model's sizes), or Pinocchio's generic algorithms again (clear_kernel).
  void set_kernel(const std::string& path);
  void clear_kernel();
  std::string kernel_path() const;  // "" where the passes are generic
  // A kernel is set and the model's joints are no longer those it was made for (a joint's
  // type, axis, pitch or mimic ratio changed in place): check_structure refuses to run it.
  bool kernel_stale() const;

 private:
  Vector6d error6(const Cut& cut) const;
  FrameMotion<double> frame_motion(pin::FrameIndex frame, bool ground) const;
  void relative_columns(Cut& cut) const;
  void relative_jacobian(const Cut& cut, bool newton);
  std::vector<DiagonalBlock> ordered_blocks() const;
  std::optional<Band> structural_band() const;
  void set_drivers(VectorXd& q, const VectorXd& drivers) const;
  void move_into(const VectorXd& q, const VectorXd& step, VectorXd& out);
  void polish(VectorXd& q, VectorXd& r, double& norm, bool factored);
  bool polish_step(VectorXd& q, VectorXd& r, double& norm, int halvings);
  double turn_between(const Node& a, const Node& b, double unit) const;
  bool newton_update(VectorXd& q, VectorXd& r, double& norm);
  // q + step taken (q, r, norm updated) where its residual is below norm; else q untouched.
  bool lowered(VectorXd& q, const VectorXd& step, VectorXd& r, double& norm);
  bool pivot_follow(const Node& node, double p_target, PathSpec& path, int why, PathResult& out);
  bool stuck(const Node& node, int why, PathResult& out) const;
  bool land_kept(const Node& start, CurvePoint a, CurvePoint b, double p_target, bool folded, PathSpec& path,
                 PathResult& out);
  void plain(const CurvePoint& a, const PathSpec& path, Node& out);
  bool singular_node(const Node& n) const;
  void curve_tangent(const VectorXd& q, const PathSpec& path, VectorXd& t);
  double curve_cos(const VectorXd& a, const VectorXd& b) const;
  int best_pivot(const VectorXd& tangent, const PathSpec& path) const;
  void curve_start(const Node& node, double sense, const PathSpec& path, CurvePoint& out);
  bool close_at(VectorXd& q, double& p, int pivot, const PathSpec& path);
  bool point_at(const CurvePoint& a, double s, const PathSpec& path, CurvePoint& out);
  bool advance(const CurvePoint& a, PathSpec& path, CurvePoint& out);
  void repivot(CurvePoint& a, const PathSpec& path) const;
  void locate_fold(CurvePoint a, CurvePoint b, const PathSpec& path, CurvePoint& out);
  void task_jacobian_into(const VectorXd& q, MatrixXd& J);
  void task_drift_into(const VectorXd& q, const VectorXd& v, VectorXd& drift);
  // The passes (kernel.cpp): forwardKinematics(q); computeJointJacobians(q) (q null: at
  // the last pass's q); forwardKinematics(q, v, a). Generated where a kernel is set.
  void kinematics_at(const VectorXd& q);
  void joint_jacobians_at(const VectorXd* q);
  void motion_at(const VectorXd& q, const VectorXd& v, const VectorXd& a);
  void kernel_inputs(const VectorXd& q, const VectorXd* v, const VectorXd* a);
  const double* kernel_placements_out();

  nb::object model_object_;  // the Python pin.Model: alive as long as this core
  const pin::Model& model_;
  pin::Data data_;
  // what the core was built on: the tree (parents), and the sizes Data is allocated to
  std::vector<pin::JointIndex> parents_;
  int nq_ = 0, nv_ = 0, nv_extended_ = 0;
  size_t nframes_ = 0;
  std::vector<pin::FrameIndex> frames_;
  std::vector<Cut> cuts_;
  Index rows_ = 0;
  std::vector<int> drv_v_, dep_v_, drv_q_, drv_continuous_;
  VectorXd dep_scale_, v_scale_, v_scale_inv_, step_, zero_;
  std::vector<std::vector<int>> blocks_rows_, blocks_cols_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> tmp3_;
  // work buffers, sized once: a pose allocates nothing
  MatrixXd J_, Jdep_, scaled_;  // J_dep and scaled_ are zero but for dep_blocks_
  std::vector<ColumnBlock> dep_blocks_;
  std::vector<Index> block_rows_, block_cols_;  // J_dep's rows and columns in block order
  std::optional<Band> band_;  // J_dep's structural band in block order (structural_band)
  std::vector<MatrixXd> block_buffers_;
  VectorXd r_, r_new_, rhs_, dstep_, drift_, q_new_, predicted_, x_;
  SquareSolve square_;
  ConditionWork condition_work_;
  double tol_;
  bool joint_jacobians_ = false;  // data_.J is at the q of the last residual_into
  std::vector<Vector6d, Eigen::aligned_allocator<Vector6d>> errors_;  // each cut's error6 there
  int iterations_ = 0;
  double moved_ = 0.0;
  int certify_every_ = CERTIFY_EVERY_POSE;
  bool certify_all_ = true;  // follow_path certifies every step (false: only a due landing)
  bool landing_due_ = true;  // ... and the step that lands on its target
  bool certify_now_ = true;  // node_at computes the condition number
  std::vector<int> pivots_;
  Node next_;  // follow_path's step buffer
  long attempts_ = 0;  // steps tried since the last look at Python's signal handlers
  // the rate task (set_task)
  std::vector<pin::FrameIndex> task_frames_;
  std::vector<std::vector<int>> task_rows_;
  std::vector<int> task_local_;
  Index task_size_ = 0;
  Matrix6Xd task_J_;
  VectorXd rate_row_scale_, rate_v_scale_;
  int rate_method_ = 0;
  double rate_damping_ = 1e-3, rate_max_condition_ = 1e8;
  std::unique_ptr<Kernel> kernel_;  // null: Pinocchio's generic passes
};

}  // namespace pinmech
