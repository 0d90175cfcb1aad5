// pinmech's compiled core: rate problems at many poses, frames along a sweep, and
// Pinocchio's own share of a pose (see core.hpp for the whole).
#include "core.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <Eigen/LU>

#include <stdexcept>

namespace pinmech {

// ---------------------------------------------------------------- rate problems
// RateSolver.solve at every row of Q, for square tasks ("exact"): closure rows stacked
// over task rows (frame Jacobian rows in world axes, or the frame's own with `local`),
// made dimensionless by `row_scale` and the velocity scale; v and a by LU. A pose whose
// stacked Jacobian is not square, or conditioned worse than max_condition, gets status
// 1 and no numbers: the Python path names it.
nb::tuple Core::rates(const Eigen::Ref<const RowMatrix>& Q, const std::vector<int>& task_frames,
                const std::vector<std::vector<int>>& task_rows, const std::vector<int>& task_local,
                const VectorXd& x_dot, const VectorXd& x_ddot, const VectorXd& row_scale, double max_condition) {
  check_structure();
  const Index n = Q.rows(), nv = model_.nv;
  Index m_task = 0;
  for (const auto& rows : task_rows) m_task += Index(rows.size());
  const Index m = rows_ + m_task;
  if (Q.cols() != model_.nq || x_dot.size() != m_task || x_ddot.size() != m_task || row_scale.size() != m ||
      task_frames.size() != task_rows.size() || task_local.size() != task_rows.size())
    throw std::invalid_argument("rates: arrays of the wrong sizes");
  for (int f : task_frames)
    if (f < 0 || size_t(f) >= frames_.size()) throw std::invalid_argument("unknown frame index");
  RowMatrix V = RowMatrix::Constant(n, nv, NAN), A = RowMatrix::Constant(n, nv, NAN);
  // condition, sigma_min, closure v and a residuals, status, then q's closure residuals
  // (independent rows, full rows: LoopSolver's is_closed reads both)
  RowMatrix numbers = RowMatrix::Constant(n, 7, NAN);
  RowMatrix achieved_v = RowMatrix::Constant(n, m_task, NAN), achieved_a = RowMatrix::Constant(n, m_task, NAN);
  {
    nb::gil_scoped_release release;
    MatrixXd J(m, nv), Jd(m, nv);
    VectorXd q(model_.nq), v(nv), a(nv), rhs(m), drift(m), x(nv), achieved(m);
    Matrix6Xd JT(6, nv);
    Eigen::PartialPivLU<MatrixXd> lu;
    ConditionWork condition_work;
    for (Index i = 0; i < n; ++i) {
      q = Q.row(i).transpose();
      if (rows_) {
        residual_into(q, r_);
        numbers(i, 5) = max_abs(r_);
        numbers(i, 6) = full_residual();
        jacobian_into(false);
        J.topRows(rows_) = J_;
      } else {
        numbers(i, 5) = numbers(i, 6) = 0.0;
        pin::computeJointJacobians(model_, data_, q);
      }
      Index row = rows_;
      for (size_t t = 0; t < task_frames.size(); ++t) {
        const pin::FrameIndex f = frames_[size_t(task_frames[t])];
        const pin::SE3& M = pin::updateFramePlacement(model_, data_, f);
        JT.setZero();
        pin::getFrameJacobian(model_, data_, f, pin::LOCAL_WORLD_ALIGNED, JT);
        if (task_local[t]) {
          tmp3_.noalias() = M.rotation().transpose() * JT.topRows<3>();
          JT.topRows<3>() = tmp3_;
          tmp3_.noalias() = M.rotation().transpose() * JT.bottomRows<3>();
          JT.bottomRows<3>() = tmp3_;
        }
        for (int k : task_rows[t]) J.row(row++) = JT.row(k);
      }
      Jd = row_scale.asDiagonal() * J * v_scale_.asDiagonal();
      if (m != nv) {
        numbers(i, 4) = 1;
        continue;
      }
      lu.compute(Jd);
      const auto [cond, smin] =
          condition_of(Jd, lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0, condition_work);
      if (!(cond < max_condition)) {
        numbers(i, 4) = 1;
        continue;
      }
      rhs.head(rows_).setZero();
      rhs.tail(m_task) = x_dot;
      x = lu.solve(row_scale.cwiseProduct(rhs));
      v = v_scale_.cwiseProduct(x);
      if (rows_) drift_into(q, v, drift_);
      else pin::forwardKinematics(model_, data_, q, v, zero_);
      drift.head(rows_) = drift_;
      row = rows_;
      for (size_t t = 0; t < task_frames.size(); ++t) {
        const pin::FrameIndex f = frames_[size_t(task_frames[t])];
        const pin::Motion acc = pin::getFrameClassicalAcceleration(model_, data_, f, pin::LOCAL_WORLD_ALIGNED);
        Vector6d e;
        e.head<3>() = acc.linear();
        e.tail<3>() = acc.angular();
        if (task_local[t]) {
          const Matrix3d RT = data_.oMf[f].rotation().transpose();
          e.head<3>() = RT * acc.linear();
          e.tail<3>() = RT * acc.angular();
        }
        for (int k : task_rows[t]) drift(row++) = e(k);
      }
      rhs.head(rows_).setZero();
      rhs.tail(m_task) = x_ddot;
      rhs -= drift;
      x = lu.solve(row_scale.cwiseProduct(rhs));
      a = v_scale_.cwiseProduct(x);
      V.row(i) = v.transpose();
      A.row(i) = a.transpose();
      achieved.noalias() = J * v;
      achieved_v.row(i) = achieved.tail(m_task).transpose();
      const double closure_v = rows_ ? max_abs(achieved.head(rows_)) : 0.0;
      achieved.noalias() = J * a;
      achieved += drift;
      achieved_a.row(i) = achieved.tail(m_task).transpose();
      const double closure_a = rows_ ? max_abs(achieved.head(rows_)) : 0.0;
      numbers.block<1, 5>(i, 0) << cond, smin, closure_v, closure_a, 0.0;
    }
  }
  return nb::make_tuple(V, A, numbers, achieved_v, achieved_a);
}

// ---------------------------------------------------------------- frames along a sweep
// Positions, rotations, velocities and classical accelerations (world axes) of frames
// at every pose: (N, F, 3) arrays and (N, F, 9) rotations, row by row.
nb::tuple Core::frame_motion(const Eigen::Ref<const RowMatrix>& Q, const Eigen::Ref<const RowMatrix>& V,
                       const Eigen::Ref<const RowMatrix>& A, const std::vector<int>& frames) {
  check_structure();
  const Index n = Q.rows(), nf = Index(frames.size());
  if (Q.cols() != model_.nq || V.cols() != model_.nv || A.cols() != model_.nv || V.rows() != n || A.rows() != n)
    throw std::invalid_argument("q, v and a of the wrong shapes");
  for (int f : frames)
    if (f < 0 || size_t(f) >= frames_.size()) throw std::invalid_argument("unknown frame index");
  RowMatrix P(n, 3 * nf), R(n, 9 * nf), Vel(n, 3 * nf), Omega(n, 3 * nf), Acc(n, 3 * nf), Alpha(n, 3 * nf);
  {
    nb::gil_scoped_release release;
    VectorXd q(model_.nq), v(model_.nv), a(model_.nv);
    for (Index i = 0; i < n; ++i) {
      q = Q.row(i).transpose();
      v = V.row(i).transpose();
      a = A.row(i).transpose();
      pin::forwardKinematics(model_, data_, q, v, a);
      for (Index k = 0; k < nf; ++k) {
        const pin::FrameIndex f = frames_[size_t(frames[size_t(k)])];
        const pin::SE3& M = pin::updateFramePlacement(model_, data_, f);
        const pin::Motion vel = pin::getFrameVelocity(model_, data_, f, pin::LOCAL_WORLD_ALIGNED);
        const pin::Motion acc = pin::getFrameClassicalAcceleration(model_, data_, f, pin::LOCAL_WORLD_ALIGNED);
        P.block<1, 3>(i, 3 * k) = M.translation().transpose();
        for (int r = 0; r < 3; ++r) R.block<1, 3>(i, 9 * k + 3 * r) = M.rotation().row(r);
        Vel.block<1, 3>(i, 3 * k) = vel.linear().transpose();
        Omega.block<1, 3>(i, 3 * k) = vel.angular().transpose();
        Acc.block<1, 3>(i, 3 * k) = acc.linear().transpose();
        Alpha.block<1, 3>(i, 3 * k) = acc.angular().transpose();
      }
    }
  }
  return nb::make_tuple(P, R, Vel, Omega, Acc, Alpha);
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
      for (int k = 0; k < jacobians; ++k) pin::computeJointJacobians(model_, data_, q);
      pin::forwardKinematics(model_, data_, q, v, zero_);
      out.block<1, 3>(i, 0) = data_.oMi[last].translation().transpose();
      out.block<1, 3>(i, 3) = (data_.oMi[last].rotation() * data_.a[last].linear()).transpose();
    }
  }
  return out;
}

}  // namespace pinmech
