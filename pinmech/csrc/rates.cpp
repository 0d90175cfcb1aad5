// pinmech's compiled core: rate problems at one pose or many, and Pinocchio's own share
// of a pose (see core.hpp for the whole).
#include "core.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <Eigen/LU>
#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace pinmech {

// ---------------------------------------------------------------- rate problems
// RateSolver.solve (pinmech/solve/rates.py states the problem and names its errors): at q,
// the closure rows stacked over the task rows (frame Jacobian rows in world axes, or the
// frame's own with `local`), J q_dot = x_dot and J q_ddot = x_ddot - Jdot q_dot, Jdot
// q_dot being each row's acceleration at zero joint acceleration (the closure drift; a
// task frame's classical acceleration after forwardKinematics(q, q_dot, 0)). Solved on J
// made dimensionless (rows times row_scale, columns times v_scale), so that the condition
// number, the minimum norm and the damping weigh a turn of one radian like a slide of one
// mechanism size.
//
// Condition number over the rank: a square J through its LU and, from 3x3 to 6x6,
// condition_of (one-sided Jacobi from 3x3 to 6x6, see condition.cpp);
// otherwise,
// or where a square J looks singular, from its singular values (Jacobi SVD). The rank is
// min(m, n) unless sigma[rank - 1] <= sigma[0] / max_condition; there it is at most
// `structural_rank`, the rank at generic poses (RateSolver._structural_rank), or, with
// structural_rank < 0, the pose gets status RATES_NEED_RANK and no numbers (the caller
// finds the structural rank and asks again).
//
// Methods (`method`: 0 exact, 1 least squares, 2 damped, as asked): damped -> damped
// least squares J^T (J J^T + damping^2 I)^-1; else a rank below the rows -> status
// RATES_INCONSISTENT unless least squares; else condition > max_condition -> status
// RATES_SINGULAR; else rank below the rows -> least squares, square -> exact (LU), wider
// -> minimum norm; least squares and minimum norm through the SVD truncated to the rank.
// The method used is returned as its code (rates.py's _USED).
namespace {

enum RateStatus { RATES_OK = 0, RATES_NEED_RANK = 1, RATES_INCONSISTENT = 2, RATES_SINGULAR = 3 };
enum RateMethodUsed { USED_EXACT = 0, USED_MINIMUM_NORM = 1, USED_LEAST_SQUARES = 2, USED_DAMPED = 3 };
constexpr int ASKED_LEAST_SQUARES = 1, ASKED_DAMPED = 2;

// Eigen's LU with partial pivoting of a square J, in fixed-size storage from 3x3 to 6x6
// (the same algorithm, its loops unrolled for the size: a third of the instructions of
// the dynamic one at 3x3, callgrind), dynamic above.
class SquareLU {
 public:
  void compute(const MatrixXd& A) {
    n_ = A.rows();
    switch (n_) {
      case 3: l3_.compute(A); break;
      case 4: l4_.compute(A); break;
      case 5: l5_.compute(A); break;
      case 6: l6_.compute(A); break;
      default: ld_.compute(A);
    }
  }
  // An exact zero pivot (J exactly singular)
  bool singular() const {
    switch (n_) {
      case 3: return zero_pivot(l3_);
      case 4: return zero_pivot(l4_);
      case 5: return zero_pivot(l5_);
      case 6: return zero_pivot(l6_);
      default: return zero_pivot(ld_);
    }
  }
  void solve(const VectorXd& b, VectorXd& x) const {
    switch (n_) {
      case 3: x = l3_.solve(Eigen::Vector3d(b)); break;
      case 4: x = l4_.solve(Eigen::Vector4d(b)); break;
      case 5: x = l5_.solve(Eigen::Matrix<double, 5, 1>(b)); break;
      case 6: x = l6_.solve(Eigen::Matrix<double, 6, 1>(b)); break;
      default: x = ld_.solve(b);
    }
  }

 private:
  template <typename LU>
  static bool zero_pivot(const LU& lu) { return lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0; }
  Index n_ = 0;
  Eigen::PartialPivLU<Eigen::Matrix3d> l3_;
  Eigen::PartialPivLU<Eigen::Matrix4d> l4_;
  Eigen::PartialPivLU<Eigen::Matrix<double, 5, 5>> l5_;
  Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> l6_;
  Eigen::PartialPivLU<MatrixXd> ld_;
};

// Work buffers of one `rates` call, sized once for all its poses.
struct RateWork {
  MatrixXd J, Jd, JJt;
  VectorXd q, b, x, rhs, drift, achieved, y;
  SquareLU lu;
  Eigen::PartialPivLU<MatrixXd> lu_damped;
  Eigen::JacobiSVD<MatrixXd> svd;
  ConditionWork condition;
  bool lu_ready = false;

  RateWork(Index m, Index nv, Index nq) : J(m, nv), Jd(m, nv), q(nq), b(m), x(nv), rhs(m), drift(m), achieved(m) {}

  // x = the method's solution of Jd x = b (Jd factored for it).
  void apply(int used, int rank) {
    if (used == USED_EXACT) {
      lu.solve(b, x);
    } else if (used == USED_DAMPED) {
      x.noalias() = Jd.transpose() * lu_damped.solve(b);
    } else {  // the pseudo-inverse truncated to the rank
      y.noalias() = svd.matrixU().leftCols(rank).transpose() * b;
      y.array() /= svd.singularValues().head(rank).array();
      x.noalias() = svd.matrixV().leftCols(rank) * y;
    }
  }
};

}  // namespace

void Core::set_task(const std::vector<int>& task_frames, const std::vector<std::vector<int>>& task_rows,
                    const std::vector<int>& task_local) {
  if (task_frames.size() != task_rows.size() || task_local.size() != task_rows.size())
    throw std::invalid_argument("set_task: frames, rows and local of different lengths");
  std::vector<pin::FrameIndex> frames;
  Index size = 0;
  for (size_t t = 0; t < task_frames.size(); ++t) {
    if (task_frames[t] < 0 || size_t(task_frames[t]) >= frames_.size())
      throw std::invalid_argument("unknown frame index");
    for (int k : task_rows[t])
      if (k < 0 || k > 5) throw std::invalid_argument("task rows are components 0 to 5");
    frames.push_back(frames_[size_t(task_frames[t])]);
    size += Index(task_rows[t].size());
  }
  task_frames_ = frames;
  task_size_ = size;
  task_rows_ = task_rows;
  task_local_ = task_local;
  task_J_ = Matrix6Xd::Zero(6, model_.nv);
}

// J (rows_ + task rows, nv) at q; leaves data_ at q with the joint Jacobians, the cut
// frames' and task frames' placements, and r_ the independent closure rows.
void Core::task_jacobian_into(const VectorXd& q, MatrixXd& J) {
  if (rows_) {
    residual_into(q, r_);
    jacobian_into(false);
    J.topRows(rows_) = J_;
  } else {
    joint_jacobians_at(&q);
  }
  Index row = rows_;
  for (size_t t = 0; t < task_frames_.size(); ++t) {
    const pin::FrameIndex f = task_frames_[t];
    const pin::SE3& M = pin::updateFramePlacement(model_, data_, f);
    task_J_.setZero();
    pin::getFrameJacobian(model_, data_, f, pin::LOCAL_WORLD_ALIGNED, task_J_);
    if (task_local_[t]) {
      tmp3_.noalias() = M.rotation().transpose() * task_J_.topRows<3>();
      task_J_.topRows<3>() = tmp3_;
      tmp3_.noalias() = M.rotation().transpose() * task_J_.bottomRows<3>();
      task_J_.bottomRows<3>() = tmp3_;
    }
    for (int k : task_rows_[t]) J.row(row++) = task_J_.row(k);
  }
}

// Jdot v of every row at (q, v): the closure drift, then the task frames' classical
// accelerations at zero joint acceleration (data_'s frame placements at q kept).
void Core::task_drift_into(const VectorXd& q, const VectorXd& v, VectorXd& drift) {
  if (rows_) {
    drift_into(q, v, drift_);
    drift.head(rows_) = drift_;
  } else {
    motion_at(q, v, zero_);
  }
  Index row = rows_;
  for (size_t t = 0; t < task_frames_.size(); ++t) {
    const pin::FrameIndex f = task_frames_[t];
    const pin::Motion acc = pin::getFrameClassicalAcceleration(model_, data_, f, pin::LOCAL_WORLD_ALIGNED);
    Vector6d e;
    e.head<3>() = acc.linear();
    e.tail<3>() = acc.angular();
    if (task_local_[t]) {
      const Matrix3d RT = data_.oMf[f].rotation().transpose();
      e.head<3>() = RT * acc.linear();
      e.tail<3>() = RT * acc.angular();
    }
    for (int k : task_rows_[t]) drift(row++) = e(k);
  }
}

MatrixXd Core::stacked_jacobian(const Eigen::Ref<const VectorXd>& q) {
  check_structure();
  if (q.size() != model_.nq) throw std::invalid_argument("stacked_jacobian: q of the wrong size");
  MatrixXd J(rows_ + task_size_, model_.nv);
  task_jacobian_into(q, J);
  return J;
}

void Core::set_rate_options(const VectorXd& row_scale, const VectorXd& v_scale, int method, double damping,
                            double max_condition) {
  if (row_scale.size() != rows_ + task_size_ || v_scale.size() != model_.nv || method < 0 || method > 2)
    throw std::invalid_argument("set_rate_options: scales of the wrong sizes, or an unknown method");
  rate_row_scale_ = row_scale;
  rate_v_scale_ = v_scale;
  rate_method_ = method;
  rate_damping_ = damping;
  rate_max_condition_ = max_condition;
}

void Core::rates(nb::handle Q_object, nb::handle x_dot_object, nb::handle x_ddot_object, int structural_rank,
                 nb::handle out_object) {
  check_structure();
  const Index nv = model_.nv, m_task = task_size_, m = rows_ + m_task;
  if (m_task == 0 || rate_row_scale_.size() != m || rate_v_scale_.size() != nv)
    throw std::invalid_argument("rates: no task or no options set (set_task, set_rate_options)");
  const Buffer bq(Q_object, 'd', -1, false, "q");
  if (model_.nq == 0 || bq.size() % model_.nq != 0) throw std::invalid_argument("q: rows of nq numbers needed");
  const Index n = bq.size() / model_.nq, width = rate_columns();
  const Buffer bxd(x_dot_object, 'd', m_task, false, "x_dot"), bxdd(x_ddot_object, 'd', m_task, false, "x_ddot");
  const Buffer bout(out_object, 'd', n * width, true, "out");
  const Eigen::Map<const RowMatrix> Q(bq.doubles(), n, model_.nq);
  const Eigen::Map<const VectorXd> x_dot(bxd.doubles(), m_task), x_ddot(bxdd.doubles(), m_task);
  Eigen::Map<RowMatrix> out(bout.doubles(), n, width);
  out.setConstant(NAN);
  auto V = out.leftCols(nv);
  auto A = out.middleCols(nv, nv);
  auto numbers = out.middleCols(2 * nv, RATE_NUMBERS);
  auto achieved_v = out.middleCols(2 * nv + RATE_NUMBERS, m_task);
  auto achieved_a = out.rightCols(m_task);
  const VectorXd& row_scale = rate_row_scale_;
  const VectorXd& v_scale = rate_v_scale_;
  const int method = rate_method_;
  const double damping = rate_damping_, max_condition = rate_max_condition_;
  {
    nb::gil_scoped_release release;
    RateWork w(m, nv, model_.nq);
    VectorXd v(nv), a(nv);
    const int full_rank = int(std::min(m, nv));
    for (Index i = 0; i < n; ++i) {
      w.q = Q.row(i).transpose();
      task_jacobian_into(w.q, w.J);
      numbers(i, 5) = rows_ ? max_abs(r_) : 0.0;
      numbers(i, 6) = rows_ ? full_residual() : 0.0;
      w.Jd.noalias() = row_scale.asDiagonal() * w.J * v_scale.asDiagonal();
      double condition = INFINITY, sigma_min = 0.0;
      int rank = full_rank;
      bool settled = false;  // the square fast path gave the condition number
      w.lu_ready = false;
      if (m == nv && m > 0) {
        w.lu.compute(w.Jd);
        w.lu_ready = true;
        const bool singular = w.lu.singular();
        double c = INFINITY, s = 0.0;
        if (!singular && n > 1 && !certify_due(certify_every_, long(i), long(n))) {
          // left uncertified (the dial): exact where it is regular, no condition number; a
          // single pose (RateSolver.solve) is certified at every level, as the pose mode
          c = s = NAN;
          condition = c;
          sigma_min = s;
          settled = true;
        } else {
          std::tie(c, s) = condition_of(w.Jd, singular, w.condition);
        }
        if (!settled && c < max_condition) {
          condition = c;
          sigma_min = s;
          settled = true;
        }
      }
      bool svd_ready = false;
      if (!settled && rank > 0) {
        w.svd.compute(w.Jd, Eigen::ComputeThinU | Eigen::ComputeThinV);
        svd_ready = true;
        const VectorXd& sigma = w.svd.singularValues();
        if (!(sigma(rank - 1) > sigma(0) / max_condition)) {
          if (structural_rank < 0) {
            numbers(i, 4) = RATES_NEED_RANK;
            continue;
          }
          rank = std::min(rank, structural_rank);
        }
        sigma_min = rank ? sigma(rank - 1) : 0.0;
        condition = sigma_min > 0 ? sigma(0) / sigma_min : INFINITY;
      }
      numbers(i, 0) = condition;
      numbers(i, 1) = sigma_min;
      numbers(i, 7) = rank;
      int used;
      if (method == ASKED_DAMPED) {
        used = USED_DAMPED;
      } else if (rank < m && method != ASKED_LEAST_SQUARES) {
        numbers(i, 4) = RATES_INCONSISTENT;
        continue;
      } else if (condition > max_condition) {
        numbers(i, 4) = RATES_SINGULAR;
        continue;
      } else if (rank < m) {
        used = USED_LEAST_SQUARES;
      } else {
        used = m == nv ? USED_EXACT : USED_MINIMUM_NORM;
      }
      if (used == USED_EXACT && !w.lu_ready) w.lu.compute(w.Jd);
      if (used == USED_DAMPED) {
        w.JJt.noalias() = w.Jd * w.Jd.transpose();
        w.JJt.diagonal().array() += damping * damping;
        w.lu_damped.compute(w.JJt);
      }
      if ((used == USED_MINIMUM_NORM || used == USED_LEAST_SQUARES) && !svd_ready)
        w.svd.compute(w.Jd, Eigen::ComputeThinU | Eigen::ComputeThinV);
      w.rhs.head(rows_).setZero();
      w.rhs.tail(m_task) = x_dot;
      w.b = row_scale.cwiseProduct(w.rhs);
      w.apply(used, rank);
      v = v_scale.cwiseProduct(w.x);
      task_drift_into(w.q, v, w.drift);
      w.rhs.head(rows_).setZero();
      w.rhs.tail(m_task) = x_ddot;
      w.rhs -= w.drift;
      w.b = row_scale.cwiseProduct(w.rhs);
      w.apply(used, rank);
      a = v_scale.cwiseProduct(w.x);
      V.row(i) = v.transpose();
      A.row(i) = a.transpose();
      w.achieved.noalias() = w.J * v;
      achieved_v.row(i) = w.achieved.tail(m_task).transpose();
      numbers(i, 2) = rows_ ? max_abs(w.achieved.head(rows_)) : 0.0;
      w.achieved.noalias() = w.J * a;
      w.achieved += w.drift;
      achieved_a.row(i) = w.achieved.tail(m_task).transpose();
      numbers(i, 3) = rows_ ? max_abs(w.achieved.head(rows_)) : 0.0;
      numbers(i, 4) = RATES_OK;
      numbers(i, 8) = used;
    }
  }
}

// ---------------------------------------------------------------- Pinocchio's share
// The Pinocchio passes alone that any certified answer at a pose needs, with nothing
// else: `jacobians` times computeJointJacobians(q) (a closed loop's Newton step at the
// predicted q, then the residual and the velocity Jacobian at the corrected q: two; an
// open chain's rates: one), then forwardKinematics(q, v, 0) (the acceleration drift).
// scripts/benchmark_peers.py times it as the cost no pinmech answer can go below.
// Returns the last joint's world position and its spatial acceleration's linear part
// (world axes, the drift at a = 0) at every pose, (N, 6), so that a test can check the
// passes ran.
RowMatrix Core::pinocchio_passes(const Eigen::Ref<const RowMatrix>& Q, const Eigen::Ref<const RowMatrix>& V,
                           int jacobians) {
  check_structure();
  const Index n = Q.rows();
  if (Q.cols() != model_.nq || V.cols() != model_.nv || V.rows() != n || jacobians < 0)
    throw std::invalid_argument("pinocchio_passes: q and v of the wrong shapes, or jacobians < 0");
  RowMatrix out(n, 6);
  {
    nb::gil_scoped_release release;
    VectorXd q(model_.nq), v(model_.nv);
    const pin::JointIndex last = pin::JointIndex(model_.njoints - 1);
    for (Index i = 0; i < n; ++i) {
      q = Q.row(i).transpose();
      v = V.row(i).transpose();
      for (int k = 0; k < jacobians; ++k) joint_jacobians_at(&q);
      motion_at(q, v, zero_);
      out.block<1, 3>(i, 0) = data_.oMi[last].translation().transpose();
      out.block<1, 3>(i, 3) = (data_.oMi[last].rotation() * data_.a[last].linear()).transpose();
    }
  }
  return out;
}

}  // namespace pinmech
