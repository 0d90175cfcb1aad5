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
std::pair<const pin::Model*, pin::Data*> borrowed_pair(nb::handle model, nb::handle data) {
  const pin::Model* m = borrow_model(model.ptr());
  pin::Data* d = borrow_data(data.ptr());
  if (m == nullptr || d == nullptr)
    throw nb::type_error("the compiled core takes a pinocchio.Model and a pinocchio.Data (from the installed pin)");
  if (d->oMi.size() != size_t(m->njoints) || d->oMf.size() != m->frames.size() || d->J.cols() != m->nvExtended)
    throw std::invalid_argument("the pin.Data is not one of this model's (model.createData())");
  return {m, d};
}

void check_ids(const Buffer& ids, Index bound, const char* what) {
  for (Py_ssize_t k = 0; k < ids.size(); ++k)
    if (ids.ints()[k] < 0 || ids.ints()[k] >= bound)
      throw std::invalid_argument(std::string(what) + " id " + std::to_string(ids.ints()[k]) + " not in the model");
}

void put_row(double* row, const pin::SE3& M, const pin::Motion& vel, const pin::Motion& acc) {
  using Map3 = Eigen::Map<Vector3d>;
  Map3 position(row), velocity(row + 12), omega(row + 15), acceleration(row + 18), angular(row + 21);
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(row + 3);
  position = M.translation();
  rotation = M.rotation();
  velocity = vel.linear();
  omega = vel.angular();
  acceleration = acc.linear();
  angular = acc.angular();  // the same in the classical and the spatial convention
}

}  // namespace

void pose_kinematics(const pin::Model& model, pin::Data& data, const double* q, const double* v, const double* a,
                     const int* frames, Index nframes, const int* joints, Index njoints, double* out) {
  using CMap = Eigen::Map<const VectorXd>;
  pin::forwardKinematics(model, data, CMap(q, model.nq), CMap(v, model.nv), CMap(a, model.nv));
  for (Index k = 0; k < nframes; ++k, out += KINEMATICS_COLUMNS) {
    const pin::FrameIndex f = pin::FrameIndex(frames[k]);
    const pin::SE3& M = pin::updateFramePlacement(model, data, f);
    put_row(out, M, pin::getFrameVelocity(model, data, f, pin::LOCAL_WORLD_ALIGNED),
            pin::getFrameClassicalAcceleration(model, data, f, pin::LOCAL_WORLD_ALIGNED));
  }
  for (Index k = 0; k < njoints; ++k, out += KINEMATICS_COLUMNS) {
    const pin::JointIndex j = pin::JointIndex(joints[k]);
    put_row(out, data.oMi[j], pin::getVelocity(model, data, j, pin::LOCAL_WORLD_ALIGNED),
            pin::getClassicalAcceleration(model, data, j, pin::LOCAL_WORLD_ALIGNED));
  }
}

void frames_at(nb::handle model_object, nb::handle data_object, nb::handle q, nb::handle v, nb::handle a,
               nb::handle frames, nb::handle joints, nb::handle out) {
  const auto [model, data] = borrowed_pair(model_object, data_object);
  const Buffer bq(q, 'd', model->nq, false, "q"), bv(v, 'd', model->nv, false, "v"), ba(a, 'd', model->nv, false, "a");
  const Buffer bf(frames, 'i', -1, false, "frames"), bj(joints, 'i', -1, false, "joints");
  check_ids(bf, Index(model->frames.size()), "frame");
  check_ids(bj, Index(model->njoints), "joint");
  const Buffer bout(out, 'd', (bf.size() + bj.size()) * KINEMATICS_COLUMNS, true, "out");
  pose_kinematics(*model, *data, bq.doubles(), bv.doubles(), ba.doubles(), bf.ints(), bf.size(), bj.ints(), bj.size(),
                  bout.doubles());
}

void frames_along(nb::handle model_object, nb::handle data_object, nb::handle Q, nb::handle V, nb::handle A,
                  nb::handle frames, nb::handle out) {
  const auto [model, data] = borrowed_pair(model_object, data_object);
  const Buffer bq(Q, 'd', -1, false, "q");
  if (model->nq == 0 || bq.size() % model->nq != 0) throw std::invalid_argument("q: rows of nq numbers needed");
  const Index n = bq.size() / model->nq;
  const Buffer bv(V, 'd', n * model->nv, false, "v"), ba(A, 'd', n * model->nv, false, "a");
  const Buffer bf(frames, 'i', -1, false, "frames");
  check_ids(bf, Index(model->frames.size()), "frame");
  const Index width = bf.size() * KINEMATICS_COLUMNS;
  const Buffer bout(out, 'd', n * width, true, "out");
  {
    nb::gil_scoped_release release;
    for (Index i = 0; i < n; ++i)
      pose_kinematics(*model, *data, bq.doubles() + i * model->nq, bv.doubles() + i * model->nv,
                      ba.doubles() + i * model->nv, bf.ints(), bf.size(), nullptr, 0, bout.doubles() + i * width);
  }
}

}  // namespace pinmech
