// pinmech's compiled core: every asked frame's and joint's placement, velocity and
// acceleration at a pose, in one call on the user's own pin.Model and pin.Data (see
// core.hpp for the whole). The one implementation behind `evaluate_motion` (one pose) and
// `frame_paths` (the poses of a sweep).
#include "core.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <stdexcept>
#include <string>

namespace pinmech {

namespace {

// The pin.Model and pin.Data inside two Python objects, or a TypeError; the Data must be
// one of that model's (as many joints and frames) or a ValueError.
std::pair<const pin::Model*, pin::Data*> borrowed_pair(const nb::object& model, const nb::object& data) {
  const pin::Model* m = borrow_model(model.ptr());
  pin::Data* d = borrow_data(data.ptr());
  if (m == nullptr || d == nullptr)
    throw nb::type_error("the compiled core takes a pinocchio.Model and a pinocchio.Data (from the installed pin)");
  if (d->oMi.size() != size_t(m->njoints) || d->oMf.size() != m->frames.size() || d->J.cols() != m->nvExtended)
    throw std::invalid_argument("the pin.Data is not one of this model's (model.createData())");
  return {m, d};
}

void check_ids(const Eigen::Ref<const Eigen::VectorXi>& ids, Index bound, const char* what) {
  for (Index k = 0; k < ids.size(); ++k)
    if (ids(k) < 0 || ids(k) >= bound)
      throw std::invalid_argument(std::string(what) + " id " + std::to_string(ids(k)) + " not in the model");
}

void put_row(double* row, const pin::SE3& M, const pin::Motion& vel, const pin::Motion& acc,
             const Vector3d& alpha) {
  using Map3 = Eigen::Map<Vector3d>;
  Map3 position(row), velocity(row + 12), omega(row + 15), acceleration(row + 18), angular(row + 21);
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(row + 3);
  position = M.translation();
  rotation = M.rotation();
  velocity = vel.linear();
  omega = vel.angular();
  acceleration = acc.linear();
  angular = alpha;
}

}  // namespace

void pose_kinematics(const pin::Model& model, pin::Data& data, const Eigen::Ref<const VectorXd>& q,
                     const Eigen::Ref<const VectorXd>& v, const Eigen::Ref<const VectorXd>& a,
                     const Eigen::Ref<const Eigen::VectorXi>& frames, const Eigen::Ref<const Eigen::VectorXi>& joints,
                     double* out) {
  pin::forwardKinematics(model, data, q, v, a);
  for (Index k = 0; k < frames.size(); ++k, out += KINEMATICS_COLUMNS) {
    const pin::FrameIndex f = pin::FrameIndex(frames(k));
    const pin::SE3& M = pin::updateFramePlacement(model, data, f);
    const pin::Motion vel = pin::getFrameVelocity(model, data, f, pin::LOCAL_WORLD_ALIGNED);
    const pin::Motion acc = pin::getFrameClassicalAcceleration(model, data, f, pin::LOCAL_WORLD_ALIGNED);
    put_row(out, M, vel, acc, acc.angular());  // angular: the same in both conventions
  }
  for (Index k = 0; k < joints.size(); ++k, out += KINEMATICS_COLUMNS) {
    const pin::JointIndex j = pin::JointIndex(joints(k));
    const pin::Motion vel = pin::getVelocity(model, data, j, pin::LOCAL_WORLD_ALIGNED);
    const pin::Motion acc = pin::getClassicalAcceleration(model, data, j, pin::LOCAL_WORLD_ALIGNED);
    put_row(out, data.oMi[j], vel, acc, acc.angular());
  }
}

RowMatrix frames_at(nb::object model_object, nb::object data_object, const Eigen::Ref<const VectorXd>& q,
                    const Eigen::Ref<const VectorXd>& v, const Eigen::Ref<const VectorXd>& a,
                    const Eigen::Ref<const Eigen::VectorXi>& frames, const Eigen::Ref<const Eigen::VectorXi>& joints) {
  const auto [model, data] = borrowed_pair(model_object, data_object);
  if (q.size() != model->nq || v.size() != model->nv || a.size() != model->nv)
    throw std::invalid_argument("frames_at: q, v, a of the wrong sizes");
  check_ids(frames, Index(model->frames.size()), "frame");
  check_ids(joints, Index(model->njoints), "joint");
  RowMatrix out(frames.size() + joints.size(), KINEMATICS_COLUMNS);
  pose_kinematics(*model, *data, q, v, a, frames, joints, out.data());
  return out;
}

RowMatrix frames_along(nb::object model_object, nb::object data_object, const Eigen::Ref<const RowMatrix>& Q,
                       const Eigen::Ref<const RowMatrix>& V, const Eigen::Ref<const RowMatrix>& A,
                       const Eigen::Ref<const Eigen::VectorXi>& frames) {
  const auto [model, data] = borrowed_pair(model_object, data_object);
  const Index n = Q.rows();
  if (Q.cols() != model->nq || V.cols() != model->nv || A.cols() != model->nv || V.rows() != n || A.rows() != n)
    throw std::invalid_argument("frames_along: q, v and a of the wrong shapes");
  check_ids(frames, Index(model->frames.size()), "frame");
  const Eigen::VectorXi no_joints(0);
  RowMatrix out(n, frames.size() * KINEMATICS_COLUMNS);
  {
    nb::gil_scoped_release release;
    for (Index i = 0; i < n; ++i)
      pose_kinematics(*model, *data, Q.row(i).transpose(), V.row(i).transpose(), A.row(i).transpose(), frames,
                      no_joints, out.row(i).data());
  }
  return out;
}

}  // namespace pinmech
