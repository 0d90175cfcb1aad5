// pinmech's compiled core: the whole of continuation.Path.follow, in the rules and
// constants continuation.py states (see core.hpp for the whole): the regular
// predictor-corrector steps (continuation.cpp's Core::step), change points kept on the
// branch of continuous tangent, and where the steps shrink below PIVOT_BELOW the solution
// curve followed with a dependent joint's coordinate as its parameter, regular through a
// fold of the driver: the fold located by bisection in that coordinate, and the target
// landed on by bisection along the curve, then Newton with the drivers held. Also the
// Newton of LoopSolver.close (full steps, else least squares with a line search).
#include "core.hpp"

#include <pinocchio/algorithm/joint-configuration.hpp>

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pinmech {

// ---------------------------------------------------------------- close
bool Core::lowered(VectorXd& q, const VectorXd& step, VectorXd& r, double& norm) {
  move_into(q, step, q_new_);
  residual_into(q_new_, r_new_);
  const double trial = max_abs(r_new_);
  if (!(trial < norm)) return false;
  q.swap(q_new_);
  r.swap(r_new_);
  norm = trial;
  return true;
}

bool Core::newton_update(VectorXd& q, VectorXd& r, double& norm) {
  // Jdep_ holds the Newton Jacobian at q (jacobian_into(true))
  if (Jdep_.rows() == Jdep_.cols()) {
    rhs_ = -r;
    square_.factor(Jdep_);
    square_.solve(rhs_, dstep_);
    if (dstep_.allFinite()) {
      if (lowered(q, dstep_, r, norm)) return true;
      residual_into(q, r);
    }
  }
  // the minimum-norm least-squares step (numpy's lstsq: singular values below
  // eps * max(m, n) * sigma_max dropped), halved until the residual decreases
  Eigen::JacobiSVD<MatrixXd> svd(Jdep_, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(std::numeric_limits<double>::epsilon() * double(std::max(Jdep_.rows(), Jdep_.cols())));
  const VectorXd step = svd.solve(VectorXd(-r));
  double alpha = 1.0;
  for (int k = 0; k < 30; ++k, alpha *= 0.5)
    if (lowered(q, alpha * step, r, norm)) return true;
  residual_into(q, r);  // data back at q
  return false;
}

// Newton with the drivers held from q; true where the loops closed (is_closed: the
// independent rows within tol, every selected row within 10 max(tol, 1e-12)). The polish
// step is taken where the residual ends between POLISH and tol, with `polish_within`
// only within max_iterations (LoopSolver.close; correct(strict=False) takes it anyway).
bool Core::close(VectorXd& q, const VectorXd& drivers, int max_iterations, bool polish_within, double& residual_left) {
  set_drivers(q, drivers);
  residual_into(q, r_);
  double norm = max_abs(r_);
  iterations_ = 0;
  moved_ = 0.0;
  while (norm > tol_ && iterations_ < max_iterations) {
    jacobian_into(true);
    ++iterations_;
    if (!newton_update(q, r_, norm)) break;
  }
  if (POLISH < norm && norm <= tol_ && tol_ <= DEFAULT_TOL && (!polish_within || iterations_ < max_iterations)) {
    jacobian_into(true);
    newton_update(q, r_, norm);  // kept only if it helps
    ++iterations_;
  }
  const double full = full_residual();
  residual_left = std::max(norm, full);
  return norm <= tol_ && full <= std::max(tol_, 1e-12) * 10;
}

nb::tuple Core::close_py(VectorXd q, const VectorXd& drivers, int max_iterations, bool polish_within) {
  check_structure();
  condition_work_.cold();
  if (q.size() != model_.nq || drivers.size() != Index(drv_q_.size()))
    throw std::invalid_argument("q or the drivers of the wrong size");
  double residual = NAN;
  const bool ok = close(q, drivers, max_iterations, polish_within, residual);
  return nb::make_tuple(q, ok, residual, iterations_);
}

nb::tuple Core::rates_at(const VectorXd& q, const VectorXd& v_drv, const VectorXd& a_drv) {
  check_structure();
  condition_work_.cold();
  if (q.size() != model_.nq || v_drv.size() != Index(drv_v_.size()) || a_drv.size() != v_drv.size())
    throw std::invalid_argument("q or the drivers' rates of the wrong size");
  if (Index(dep_v_.size()) != rows_) throw std::invalid_argument("the dependent Jacobian must be square");
  Node out;
  out.q = q;
  residual_into(q, r_);
  out.residual = std::max(max_abs(r_), full_residual());
  node_at(out, v_drv, &a_drv);
  return nb::make_tuple(out.d1, out.d2, out.signs, out.condition, out.sigma_min, out.velocity_residual,
                        out.acceleration_residual, out.residual);
}

// ---------------------------------------------------------------- Path.follow
void Core::follow_path(Node& node, double p_target, PathSpec& path, PathResult& out) {
  const double unit = path.unit;
  double h = std::copysign(std::min(std::abs(p_target - node.p), MAX_STEP / unit), p_target - node.p);
  int why = 0;
  Node& next = next_;  // a buffer kept across calls: a regular pose allocates nothing
  while (node.p != p_target) {
    if (++attempts_ % SIGNAL_EVERY == 0) check_signals();
    const double remaining = p_target - node.p;
    h = std::copysign(std::min(std::abs(h), std::abs(remaining)), remaining);
    bool change = false;
    const bool lands = !(std::abs(h) < std::abs(remaining));
    certify_now_ = certify_all_ || (landing_due_ && lands);
    const int code = step(node, lands ? p_target : node.p + h, path.x0, path.d, unit, next, change);
    certify_now_ = true;
    // Refused among uncertified poses: singular, not finite, turning, another signature, or
    // a step that would need the pivot. The range mode follows again from its
    // last certified pose, certifying every pose. A corrector or trust-region refusal (1, 2)
    // halves the step as at every pose: step control, not certification.
    if (code != 0 && !certify_all_ && (code >= 3 || std::abs(h) * unit <= PIVOT_BELOW)) {
      out.status = PATH_REFUSED;
      out.why = code;
      return;
    }
    if (code == 0 || (code == 5 && change)) {
      if (next.signs != node.signs) out.change_points.push_back(0.5 * (node.p + next.p));
      std::swap(node, next);
      ++out.steps;
      out.iterations += iterations_;
      h *= 2.0;
      continue;
    }
    why = code;
    if (code == 5) {
      out.signs_a = node.signs;
      out.signs_b = next.signs;
    }
    if (std::abs(h) * unit > PIVOT_BELOW) {
      h *= 0.5;
      continue;
    }
    if (!pivot_follow(node, p_target, path, why, out)) return;
    node = out.node;
    p_target = out.p_target;
    h = p_target - node.p;
  }
  out.status = PATH_DONE;
  std::swap(out.node, node);
  out.p_target = p_target;
}

bool Core::stuck(const Node& node, int why, PathResult& out) const {
  out.status = PATH_STUCK;
  out.why = why;
  out.node = node;
  return false;
}

bool Core::singular_node(const Node& n) const {
  if (!(n.condition <= SINGULAR_NODE)) return true;
  for (int s : n.signs)
    if (s == 0) return true;
  return false;
}

// Path._pivot_follow: the curve from `node` to p_target or a fold; true with out.node
// and out.p_target (mirrored past folds crossed) where it landed, else out says why not.
bool Core::pivot_follow(const Node& node, double p_target, PathSpec& path, int why, PathResult& out) {
  if (path.scalar.empty()) return stuck(node, NO_PIVOT, out);
  path.ds = 1e-3;
  double sense = p_target > node.p ? 1.0 : -1.0;
  CurvePoint state, next, fold;
  curve_start(node, sense, path, state);
  bool folded = false;
  for (long i = 0; i < MAX_PIVOT_STEPS; ++i) {
    if (++attempts_ % SIGNAL_EVERY == 0) check_signals();
    if (!advance(state, path, next)) return stuck(node, why, out);
    if (next.dp() * state.dp() <= 0) {  // the driver turned back: a fold in between
      locate_fold(state, next, path, fold);
      if ((fold.p - p_target) * sense >= 0)  // the target comes before the fold
        return land_kept(node, state, fold, p_target, folded, path, out);
      if (!path.through_folds) {
        out.status = PATH_FOLD;
        out.node = node;
        out.fold = fold.p;
        out.p_target = p_target;
        return false;
      }
      out.folds.push_back(fold.p);
      p_target = 2.0 * fold.p - p_target;
      sense = -sense;
      folded = true;
    } else if ((next.p - p_target) * sense >= 0) {  // passed the target: close there
      return land_kept(node, state, next, p_target, folded, path, out);
    }
    repivot(next, path);
    std::swap(state, next);
  }
  return stuck(node, why, out);
}

// Path._land then Path._kept: the pose at p_target between two curve points that
// bracket it, by bisection along the curve to LAND_TOL of driver motion, then Newton with
// the drivers held; it must keep the assembly of the point before it, and of `start`
// where no fold was crossed (a curve that comes within rounding of another assembly).
bool Core::land_kept(const Node& start, CurvePoint a, CurvePoint b, double p_target, bool folded, PathSpec& path,
                     PathResult& out) {
  CurvePoint mid;
  for (int k = 0; k < 60; ++k) {
    if (std::abs(b.p - a.p) * path.unit <= LAND_TOL) break;
    if (!point_at(a, 0.5 * (a.s + b.s), path, mid)) break;
    if ((mid.p - p_target) * (a.p - p_target) > 0) std::swap(a, mid);
    else std::swap(b, mid);
  }
  const double w = b.p != a.p ? (p_target - a.p) / (b.p - a.p) : 0.0;
  VectorXd dq(model_.nv), q(model_.nq);
  pin::difference(model_, a.q, b.q, dq);
  pin::integrate(model_, a.q, VectorXd(w * dq), q);
  x_ = path.x0 + p_target * path.d;
  double residual = NAN;
  Node before;
  if (!close(q, x_, LAND_ITERATIONS, false, residual)) {
    plain(a, path, before);
    return stuck(before, TARGET_NOT_CLOSED, out);
  }
  Node landed;
  landed.p = p_target;
  landed.q = q;
  landed.residual = residual;
  node_at(landed, path.d);
  if (singular_node(landed)) {
    out.status = PATH_SINGULAR;
    out.node = landed;
    return false;
  }
  plain(a, path, before);
  if (landed.signs != before.signs) return stuck(before, TARGET_ON_ANOTHER, out);
  if (!folded && landed.signs != start.signs) {
    out.signs_a = start.signs;
    out.signs_b = landed.signs;
    return stuck(start, ANOTHER_ASSEMBLY_NEAR, out);
  }
  out.node = landed;
  out.p_target = p_target;
  return true;
}

// Path._plain: a curve point as a node (no signature where it is singular).
void Core::plain(const CurvePoint& a, const PathSpec& path, Node& out) {
  out.p = a.p;
  out.q = a.q;
  residual_into(a.q, r_);
  out.residual = std::max(max_abs(r_), full_residual());
  node_at(out, path.d);
  if (singular_node(out)) {
    out.signs.clear();
    out.condition = INFINITY;
  }
}

// ---------------------------------------------------------------- the curve (continuation._Curve)
// Unit tangent at a closed q, unoriented: the null vector of [J_dep diag(dep_scale), J_drv
// d_hat], as dq in velocity space and, last, the drivers' motion in radians or sizes.
void Core::curve_tangent(const VectorXd& q, const PathSpec& path, VectorXd& t) {
  residual_into(q, r_);
  jacobian_into(false);
  const Index ndep = Index(dep_v_.size());
  MatrixXd A(rows_, ndep + 1);
  A.leftCols(ndep) = Jdep_ * dep_scale_.asDiagonal();
  A.col(ndep).setZero();
  for (size_t i = 0; i < drv_v_.size(); ++i) A.col(ndep) += J_.col(drv_v_[i]) * path.d_hat(Index(i));
  Eigen::JacobiSVD<MatrixXd> svd(A, Eigen::ComputeFullV);
  const VectorXd null = svd.matrixV().col(ndep);
  t = VectorXd::Zero(model_.nv + 1);
  for (Index i = 0; i < ndep; ++i) t(dep_v_[size_t(i)]) = null(i) * dep_scale_(i);
  for (size_t i = 0; i < drv_v_.size(); ++i) t(drv_v_[i]) = null(ndep) * path.d_hat(Index(i));
  t(model_.nv) = null(ndep);
}

// The cosine of the angle between two tangents made dimensionless (joint rates over their
// velocity scales; the last entry is in radians or sizes already).
double Core::curve_cos(const VectorXd& a, const VectorXd& b) const {
  const Index nv = model_.nv;
  VectorXd ua(nv + 1), ub(nv + 1);
  ua << a.head(nv).cwiseProduct(v_scale_inv_), a(nv);
  ub << b.head(nv).cwiseProduct(v_scale_inv_), b(nv);
  return ua.dot(ub) / (ua.norm() * ub.norm());
}

int Core::best_pivot(const VectorXd& tangent, const PathSpec& path) const {
  int best = path.scalar.front();
  for (int v : path.scalar)
    if (std::abs(tangent(v) * v_scale_inv_(v)) > std::abs(tangent(best) * v_scale_inv_(best))) best = v;
  return best;
}

void Core::curve_start(const Node& node, double sense, const PathSpec& path, CurvePoint& out) {
  VectorXd t;
  curve_tangent(node.q, path, t);
  VectorXd along(model_.nv + 1);
  along << node.d1 / path.unit, 1.0;
  along *= sense;
  if (curve_cos(t, along) < 0) t = -t;
  out.p = node.p;
  out.q = node.q;
  out.s = 0.0;
  out.pivot = best_pivot(t, path);
  out.tangent = std::move(t);
}

// Newton on (the other dependent joints, p) with the pivot held where q has it; each
// iteration must halve the residual.
bool Core::close_at(VectorXd& q, double& p, int pivot, const PathSpec& path) {
  std::vector<int> others;
  for (int v : dep_v_)
    if (v != pivot) others.push_back(v);
  if (Index(others.size()) + 1 != rows_) return false;  // not square: numpy's solve refused it
  x_ = path.x0 + p * path.d;
  set_drivers(q, x_);
  residual_into(q, r_);
  double norm = max_abs(r_);
  MatrixXd A(rows_, rows_);
  VectorXd dv = VectorXd::Zero(model_.nv), moved(model_.nq);
  for (int it = 0; it < CORRECTOR_ITERATIONS + 4; ++it) {
    if (norm <= tol_) return true;
    jacobian_into(true);
    for (size_t i = 0; i < others.size(); ++i) A.col(Index(i)) = J_.col(others[i]);
    A.col(rows_ - 1).setZero();
    for (size_t i = 0; i < drv_v_.size(); ++i) A.col(rows_ - 1) += J_.col(drv_v_[i]) * path.d_hat(Index(i));
    const Eigen::PartialPivLU<MatrixXd> lu(A);
    if (lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0) return false;
    const VectorXd step = lu.solve(VectorXd(-r_));
    if (!step.allFinite()) return false;
    dv.setZero();
    for (size_t i = 0; i < others.size(); ++i) dv(others[i]) = step(Index(i));
    p += step(rows_ - 1) / path.unit;
    pin::integrate(model_, q, dv, moved);
    q = moved;
    x_ = path.x0 + p * path.d;
    set_drivers(q, x_);
    residual_into(q, r_new_);
    const double new_norm = max_abs(r_new_);
    if (new_norm > 0.5 * norm && new_norm > tol_) return false;
    r_.swap(r_new_);
    norm = new_norm;
  }
  return norm <= tol_;
}

// The curve point with a's pivot at s (moved by s - a.s from a), or false: its Newton
// failed, it left the trust region, or the tangent turned more than MAX_TURN.
bool Core::point_at(const CurvePoint& a, double s, const PathSpec& path, CurvePoint& out) {
  const Index nv = model_.nv;
  const double scale = (s - a.s) / a.tangent(a.pivot);
  const VectorXd move = a.tangent.head(nv) * scale;
  VectorXd guess(model_.nq);
  pin::integrate(model_, a.q, move, guess);
  VectorXd q = guess;
  double p = a.p + a.tangent(nv) * scale / path.unit;
  if (!close_at(q, p, a.pivot, path)) return false;
  VectorXd dq(nv);
  pin::difference(model_, guess, q, dq);
  if (max_abs(dq.cwiseProduct(v_scale_inv_)) > TRUST * max_abs(move.cwiseProduct(v_scale_inv_)) + 1e3 * tol_)
    return false;
  VectorXd t;
  curve_tangent(q, path, t);
  double cos = curve_cos(t, a.tangent);
  if (cos < 0) {
    t = -t;
    cos = -cos;
  }
  if (cos < std::cos(MAX_TURN)) return false;
  out.p = p;
  out.q = std::move(q);
  out.s = s;
  out.tangent = std::move(t);
  out.pivot = a.pivot;
  return true;
}

// The next curve point, with an adaptive pivot step (false where none is found).
bool Core::advance(const CurvePoint& a, PathSpec& path, CurvePoint& out) {
  for (double ds = path.ds; ds >= 1e-14; ds *= 0.5) {
    if (point_at(a, a.s + std::copysign(ds, a.tangent(a.pivot)), path, out)) {
      path.ds = std::min(ds * 1.5, 0.05);
      return true;
    }
  }
  return false;
}

// a with the fastest-moving joint as its pivot (s from 0) where the current one moves
// less than half as fast.
void Core::repivot(CurvePoint& a, const PathSpec& path) const {
  const int best = best_pivot(a.tangent, path);
  if (best != a.pivot && std::abs(a.tangent(a.pivot) * v_scale_inv_(a.pivot)) <
                             0.5 * std::abs(a.tangent(best) * v_scale_inv_(best))) {
    a.pivot = best;
    a.s = 0.0;
  }
}

// The curve point between a and b (one pivot) where dp changes sign, by bisection in the
// pivot's coordinate to FOLD_TOL.
void Core::locate_fold(CurvePoint a, CurvePoint b, const PathSpec& path, CurvePoint& out) {
  CurvePoint mid;
  while (std::abs(b.s - a.s) > FOLD_TOL) {
    if (!point_at(a, 0.5 * (a.s + b.s), path, mid)) break;
    if (mid.dp() * a.dp() > 0) std::swap(a, mid);
    else std::swap(b, mid);
  }
  out = std::abs(a.dp()) < std::abs(b.dp()) ? a : b;
}

nb::tuple Core::follow_path_py(double p0, const VectorXd& q0, const VectorXd& d1, const VectorXd& d2,
                               const std::vector<int>& signs0, double condition0, const VectorXd& x0,
                               const VectorXd& d, double unit, double p_target, bool through_folds,
                               const std::vector<int>& scalar) {
  check_structure();
  condition_work_.cold();
  if (q0.size() != model_.nq || d1.size() != model_.nv || d2.size() != model_.nv ||
      d.size() != Index(drv_v_.size()) || x0.size() != d.size())
    throw std::invalid_argument("follow_path: arrays of the wrong size");
  if (Index(dep_v_.size()) != rows_) throw std::invalid_argument("the dependent Jacobian must be square");
  for (int v : scalar)
    if (v < 0 || v >= model_.nv) throw std::invalid_argument("pivot index not in the model");
  PathSpec path = make_path(x0, d, unit, through_folds, scalar);
  Node node = start_node(p0, q0, d1, d2, signs0, condition0);
  PathResult out;
  {
    nb::gil_scoped_release release;
    follow_path(node, p_target, path, out);
  }
  const Node& n = out.node;
  nb::dict numbers;
  numbers["status"] = out.status;
  numbers["why"] = out.why;
  numbers["p_target"] = out.p_target;
  numbers["fold"] = out.fold;
  numbers["steps"] = out.steps;
  numbers["iterations"] = out.iterations;
  numbers["change_points"] = out.change_points;
  numbers["folds"] = out.folds;
  numbers["signs_a"] = out.signs_a;
  numbers["signs_b"] = out.signs_b;
  return nb::make_tuple(numbers, n.p, n.q, n.d1, n.d2, n.signs, n.condition, n.sigma_min, n.velocity_residual,
                        n.acceleration_residual, n.residual);
}

}  // namespace pinmech
