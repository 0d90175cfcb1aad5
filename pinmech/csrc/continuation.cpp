// pinmech's compiled core: the corrector, the predictor-corrector steps and the sweeps
// (see core.hpp for the whole).
#include "core.hpp"

#include <pinocchio/algorithm/joint-configuration.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pinmech {

// Run Python's signal handlers (Ctrl-C, SIGTERM: pinmech's raise Interrupted) from a loop
// that released the GIL, and leave the loop with the exception they raised.
void check_signals() {
  nb::gil_scoped_acquire acquire;
  if (PyErr_CheckSignals() != 0) throw nb::python_error();
}

// ---------------------------------------------------------------- the corrector
// LoopSolver.correct(strict=True): full Newton steps, each at least halving the
// residual; the polish step of `close`; the full-residual check. False: no root here.
bool Core::correct(VectorXd& q, const VectorXd& drivers, int max_iterations, double& residual_left) {
  set_drivers(q, drivers);
  VectorXd& r = r_;
  residual_into(q, r, true);  // a predicted pose: Newton's Jacobian is taken there
  double norm = max_abs(r);
  iterations_ = 0;
  moved_ = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    if (norm <= tol_) break;
    jacobian_into(true);
    ++iterations_;
    rhs_ = -r;
    square_.factor(Jdep_);
    square_.solve(rhs_, dstep_);
    if (!dstep_.allFinite()) return false;
    move_into(q, dstep_, q_new_);
    residual_into(q_new_, r_new_);
    const double new_norm = max_abs(r_new_);
    if (new_norm > 0.5 * norm && new_norm > tol_) {
      residual_into(q, r);
      return false;
    }
    q.swap(q_new_);
    r.swap(r_new_);
    norm = new_norm;
  }
  if (POLISH < norm && norm <= tol_ && tol_ <= DEFAULT_TOL) {
    polish(q, r, norm, iterations_ > 0);
    ++iterations_;
  }
  const double full = full_residual();
  if (norm > tol_ || full > std::max(tol_, 1e-12) * 10) return false;
  residual_left = std::max(norm, full);
  return true;
}

// ---------------------------------------------------------------- nodes and steps
// Path.node at a closed q whose placements and Jacobians are in data_: the path
// derivatives at driver velocity d, the condition number and the signature.
void Core::node_at(Node& node, const VectorXd& d, const VectorXd* a_drv) {
  // One factorization of the dimensionless J_dep (columns times dep_scale_) serves the
  // condition number and both solves; a dependent rate is dep_scale_ times its unknown.
  jacobian_into(false);
  for (const ColumnBlock& b : dep_blocks_)  // J_dep times dep_scale_'s diagonal, where not structurally zero
    scaled_.block(b.offset, b.dep, b.rows, 1) = Jdep_.block(b.offset, b.dep, b.rows, 1) * dep_scale_(b.dep);
  square_.factor(scaled_);
  if (certify_now_) {
    // The condition number of J_dep, with its rows and columns in block order where it has
    // several blocks (a permutation: the same singular values), where a chain of loops is a
    // band matrix.
    auto [condition, sigma_min] =
        condition_of(scaled_, square_.singular(), condition_work_, band_ ? &*band_ : nullptr);
    node.condition = condition;
    node.sigma_min = sigma_min;
  } else {  // left uncertified (the dial): no condition number; the signature below all the same
    node.condition = NAN;
    node.sigma_min = NAN;
  }
  signs_into(Jdep_, node.signs);  // a determinant's sign a block: every pose keeps its assembly check
  VectorXd &v = node.d1, &a = node.d2;
  v.setZero(model_.nv);
  a.setZero(model_.nv);
  for (size_t i = 0; i < drv_v_.size(); ++i) v(drv_v_[i]) = d(Index(i));
  rhs_.setZero();
  for (size_t i = 0; i < drv_v_.size(); ++i) rhs_.noalias() -= J_.col(drv_v_[i]) * d(Index(i));  // v's only nonzeros yet
  square_.solve(rhs_, dstep_);
  for (size_t i = 0; i < dep_v_.size(); ++i) v(dep_v_[i]) = dep_scale_(Index(i)) * dstep_(Index(i));
  drift_into(node.q, v, drift_);
  rhs_ = -drift_;
  if (a_drv != nullptr) {
    for (size_t i = 0; i < drv_v_.size(); ++i) a(drv_v_[i]) = (*a_drv)(Index(i));
    for (size_t i = 0; i < drv_v_.size(); ++i) rhs_.noalias() -= J_.col(drv_v_[i]) * a(drv_v_[i]);  // a's only nonzeros yet
  }
  square_.solve(rhs_, dstep_);
  for (size_t i = 0; i < dep_v_.size(); ++i) a(dep_v_[i]) = dep_scale_(Index(i)) * dstep_(Index(i));
  rows_times(v, rhs_);
  node.velocity_residual = max_abs(rhs_);
  rows_times(a, rhs_);
  rhs_ += drift_;
  node.acceleration_residual = max_abs(rhs_);
}

// Path.step from `from` to p; 0 and `out` filled on success, else why it failed:
// 1 corrector, 2 trust region, 3 singular, 4 turn, 5 signature changed (a change point
// when `change` is set: follow_path keeps it, on the branch of continuous tangent).
int Core::step(const Node& from, double p, const VectorXd& x0, const VectorXd& d, double unit, Node& out, bool& change) {
  change = false;
  const double h = p - from.p;
  predicted_ = from.d1 * h + from.d2 * (0.5 * h * h);
  VectorXd& q = out.q;
  q.resize(model_.nq);
  pin::integrate(model_, from.q, predicted_, q);
  double residual_left = 0.0;
  x_ = x0 + p * d;
  if (!correct(q, x_, CORRECTOR_ITERATIONS, residual_left)) return 1;
  const double trust = std::min(TRUST, 2.0 * std::abs(h) * unit);
  if (moved_ > trust * max_abs(predicted_.cwiseProduct(v_scale_inv_)) + 1e3 * tol_) return 2;
  out.p = p;
  out.residual = residual_left;
  node_at(out, d);
  if (!certify_now_) {  // residuals, trust region, turn and signature: all but the condition number
    for (int s : out.signs)
      if (s == 0) return 3;
    if (square_.singular() || !out.d1.allFinite() || !out.d2.allFinite()) return 3;
    if (turn_between(from, out, unit) > MAX_TURN) return 4;
    return out.signs != from.signs ? 5 : 0;  // refused: followed again, every pose certified
  }
  for (int s : out.signs)
    if (s == 0) return 3;
  if (!(out.condition <= SINGULAR_NODE) || within_reach_of_singular(out.residual, out.sigma_min)) return 3;
  const double turn = turn_between(from, out, unit);
  if (turn > MAX_TURN) return 4;
  if (out.signs != from.signs) {
    change = std::abs(h) * unit <= 1e-3 && turn < 0.1 * MAX_TURN;
    return 5;
  }
  return 0;
}


// The range mode of solve_cycle._Cycle: from the node (p0, q0, d1, d2) along drivers
// x(p) = x0 + p d to each of `targets` in turn, each by Path.follow (follow_path, the one
// implementation of the step rules). It stops where a target needs more than the range
// mode states: a change point passed or a fold met (the pose-by-pose follow then names
// and notes it), a pose worse conditioned than max_condition, or rates that overflow.
// Returns (poses done, why it stopped, q, d1, d2, accuracy columns).
nb::tuple Core::follow(double p0, const VectorXd& q0, const VectorXd& d1, const VectorXd& d2, const std::vector<int>& signs0,
                 double condition0, const VectorXd& x0, const VectorXd& d, double unit, const VectorXd& targets,
                 double max_condition) {
  check_structure();
  condition_work_.cold();
  if (Index(dep_v_.size()) != rows_) throw std::invalid_argument("the dependent Jacobian must be square");
  const Index n = targets.size();
  RowMatrix Q(n, model_.nq), D1(n, model_.nv), D2(n, model_.nv);
  RowMatrix acc(n, 7);  // residual, iterations, condition, sigma_min, velocity and acceleration residuals, steps
  Index done = 0;
  int stop = DONE;
  {
    nb::gil_scoped_release release;
    PathSpec path = make_path(x0, d, unit, false, pivots_);
    Node node = start_node(p0, q0, d1, d2, signs0, condition0);
    // The dial: poses left without their condition number between certified ones. Where a
    // step among them is refused (singular, not finite, turning, another signature), or a
    // certified pose finds a condition number over max_condition, the range is followed
    // again from the last certified pose with every pose certified up to that one, so it
    // stops, names and locates as at every pose.
    Node certified = node;
    Index certified_done = 0, full_until = -1;
    struct Restore {  // the pose mode certifies every pose, whatever ends this loop
      Core& core;
      ~Restore() { core.certify_all_ = core.landing_due_ = core.certify_now_ = true; }
    } restore{*this};
    while (done < n && stop == DONE) {
      certify_all_ = certify_every_ == CERTIFY_EVERY_POSE || done <= full_until;
      landing_due_ = certify_all_ || certify_due(certify_every_, done, n);
      PathResult out;
      follow_path(node, targets(done), path, out);
      const bool uncertified_run = !certify_all_;
      if (out.status == PATH_REFUSED) {
        full_until = done;
        node = certified;
        done = certified_done;
        continue;
      }
      if (out.status != PATH_DONE || !out.change_points.empty() || !out.folds.empty()) {
        stop = out.status == PATH_DONE ? SIGNATURE_CHANGED : NEEDS_PIVOT;
        break;
      }
      std::swap(node, out.node);
      const bool bad_condition = node.condition > max_condition;
      const bool not_finite = !node.d1.allFinite() || !node.d2.allFinite();
      if (uncertified_run && (bad_condition || not_finite)) {
        full_until = done;
        node = certified;
        done = certified_done;
        continue;
      }
      if (bad_condition) {
        stop = CONDITION;
        break;
      }
      if (not_finite) {
        stop = NOT_FINITE;
        break;
      }
      Q.row(done) = node.q.transpose();
      D1.row(done) = node.d1.transpose();
      D2.row(done) = node.d2.transpose();
      acc.row(done) << node.residual, double(out.iterations), node.condition, node.sigma_min, node.velocity_residual,
          node.acceleration_residual, double(out.steps);
      ++done;
      if (landing_due_) {
        certified = node;
        certified_done = done;
      }
    }
  }
  return nb::make_tuple(done, stop, Q.topRows(done).eval(), D1.topRows(done).eval(), D2.topRows(done).eval(),
                        acc.topRows(done).eval());
}

void Core::set_certify_every(int every) {
  if (every < CERTIFY_NONE) throw std::invalid_argument("certify_every: -1 (none), 0 (ends), 1 (every pose) or k >= 2");
  certify_every_ = every;
}

void Core::set_pivots(const std::vector<int>& scalar) {
  for (int v : scalar)
    if (v < 0 || v >= model_.nv) throw std::invalid_argument("pivot index " + std::to_string(v) + " not in the model");
  pivots_ = scalar;
}

// Path.node at a closed q: the path derivatives at driver velocity d, the signature,
// the condition number and the residuals (closure, velocity, acceleration).
nb::tuple Core::node(const VectorXd& q, const VectorXd& d) {
  check_structure();
  condition_work_.cold();
  if (q.size() != model_.nq || d.size() != Index(drv_v_.size())) throw std::invalid_argument("q or d of the wrong size");
  Node out;
  out.q = q;
  residual_into(q, r_);
  out.residual = std::max(max_abs(r_), full_residual());
  node_at(out, d);
  return nb::make_tuple(out.d1, out.d2, out.signs, out.condition, out.sigma_min, out.velocity_residual,
                        out.acceleration_residual, out.residual);
}

void Core::set_drivers(VectorXd& q, const VectorXd& drivers) const {
  for (size_t i = 0; i < drv_q_.size(); ++i) {
    const double x = drivers(Index(i));
    if (drv_continuous_[i]) {
      q(drv_q_[i]) = std::cos(x);
      q(drv_q_[i] + 1) = std::sin(x);
    } else {
      q(drv_q_[i]) = x;
    }
  }
}

// LoopSolver._move: q moved by a step of the dependent joints, at most MAX_NEWTON_STEP.
void Core::move_into(const VectorXd& q, const VectorXd& step, VectorXd& out) {
  const double size = max_abs(step.cwiseQuotient(dep_scale_));
  const double shrink = size > MAX_NEWTON_STEP ? MAX_NEWTON_STEP / size : 1.0;
  moved_ += std::min(size, MAX_NEWTON_STEP);
  step_.setZero();
  for (size_t i = 0; i < dep_v_.size(); ++i) step_(dep_v_[i]) = shrink * step(Index(i));
  out.resize(model_.nq);
  pin::integrate(model_, q, step_, out);
}


// LoopSolver._newton_update at the polish: the full step if it lowers the residual,
// else the step halved until it does (a square regular J_dep: least squares is Newton).
// `factored`: square_ holds J_dep factored at the last Newton iterate, one step before q;
// its full step (a chord step: from a residual near tol it lands within rounding, as
// Newton's does, the step between the two Jacobians being small) is tried first and kept
// where it lowers the residual, else the polish is Newton's at q.
void Core::polish(VectorXd& q, VectorXd& r, double& norm, bool factored) {
  if (factored && polish_step(q, r, norm, 0)) return;
  jacobian_into(true);
  square_.factor(Jdep_);
  polish_step(q, r, norm, LINE_SEARCH_HALVINGS);
}

// The step of square_'s factorization from q, halved up to `halvings` times until it
// lowers the residual (q, r, norm then updated; true); else data_ is left at q.
bool Core::polish_step(VectorXd& q, VectorXd& r, double& norm, int halvings) {
  rhs_ = -r;
  square_.solve(rhs_, dstep_);
  if (!dstep_.allFinite()) return false;
  for (int k = 0; k <= halvings; ++k, dstep_ *= 0.5) {  // halving: exact
    move_into(q, dstep_, q_new_);
    residual_into(q_new_, r_new_);
    const double trial_norm = max_abs(r_new_);
    if (trial_norm < norm) {
      q.swap(q_new_);
      r.swap(r_new_);
      norm = trial_norm;
      return true;
    }
  }
  residual_into(q, r);  // data back at q
  return false;
}

double Core::turn_between(const Node& a, const Node& b, double unit) const {
  const auto ta = a.d1.cwiseProduct(v_scale_inv_), tb = b.d1.cwiseProduct(v_scale_inv_);  // lazy: no temporaries
  const double na = std::sqrt(ta.squaredNorm() + unit * unit), nb_ = std::sqrt(tb.squaredNorm() + unit * unit);
  const double c = (ta.dot(tb) + unit * unit) / (na * nb_);
  return std::acos(std::max(-1.0, std::min(1.0, c)));
}

}  // namespace pinmech
