// pinmech's compiled core: the kinematic passes the engine runs, Pinocchio's generic
// algorithms or a generated kernel of the same algorithms specialised to the model
// (pinmech/kernelgen/generator.cpp writes it; pinmech/solve/kernels.py compiles, caches and
// verifies it). Either way the pass leaves in data_ what the rest of the core reads:
// oMi, and data.J, or data.v and data.a. Nothing downstream knows which ran.
#include "core.hpp"

#include <dlfcn.h>

#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <stdexcept>
#include <string>

namespace pinmech {

namespace {

constexpr int KERNEL_ABI = 1;  // generator.cpp's

template <typename F>
F symbol(void* handle, const char* name, const std::string& path) {
  void* address = dlsym(handle, name);
  if (address == nullptr) throw std::invalid_argument("the kernel " + path + " has no " + name);
  return reinterpret_cast<F>(address);
}

}  // namespace

Kernel::~Kernel() {
  if (handle != nullptr) dlclose(handle);
}

void Core::set_kernel(const std::string& path) {
  if (!same_structure()) check_structure();  // a stale kernel is what this replaces
  auto kernel = std::make_unique<Kernel>();
  kernel->handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (kernel->handle == nullptr) throw std::invalid_argument("cannot load the kernel " + path + ": " + dlerror());
  int shape[5] = {0, 0, 0, 0, 0};
  symbol<void (*)(int*)>(kernel->handle, "pinmech_kernel_shape", path)(shape);
  if (shape[0] != KERNEL_ABI || shape[1] != model_.nq || shape[2] != model_.nv || shape[3] != model_.nvExtended ||
      shape[4] != model_.njoints)
    throw std::invalid_argument("the kernel " + path + " was generated for another model (nq " +
                                std::to_string(shape[1]) + ", nv " + std::to_string(shape[2]) + ", joints " +
                                std::to_string(shape[4]) + "; this one: nq " + std::to_string(model_.nq) + ", nv " +
                                std::to_string(model_.nv) + ", joints " + std::to_string(model_.njoints) + ")");
  kernel->placements = symbol<Kernel::Pass>(kernel->handle, "pinmech_kernel_placements", path);
  kernel->jacobians = symbol<Kernel::Pass>(kernel->handle, "pinmech_kernel_jacobians", path);
  kernel->motion = symbol<Kernel::Pass>(kernel->handle, "pinmech_kernel_motion", path);
  const Index nj = model_.njoints - 1;
  kernel->x = VectorXd::Zero(model_.nq + 2 * model_.nv + 12 * nj);
  kernel->y = VectorXd::Zero(12 * nj + std::max<Index>(6 * model_.nvExtended, 12 * nj));
  kernel->path = path;
  kernel->joints = model_.joints;
  kernel_ = std::move(kernel);
  joint_jacobians_ = false;
}

void Core::clear_kernel() {
  kernel_.reset();
  joint_jacobians_ = false;
}

std::string Core::kernel_path() const { return kernel_ ? kernel_->path : std::string(); }

bool Core::kernel_stale() const { return kernel_ && !(model_.joints == kernel_->joints); }

// The kernel's input: q, v, a and the model's joint placements as they are now (a
// dimension changed in the model is used at the next call).
void Core::kernel_inputs(const VectorXd& q, const VectorXd* v, const VectorXd* a) {
  VectorXd& x = kernel_->x;
  const Index nq = model_.nq, nv = model_.nv;
  x.head(nq) = q;
  if (v != nullptr) x.segment(nq, nv) = *v;
  if (a != nullptr) x.segment(nq + nv, nv) = *a;
  double* p = x.data() + nq + 2 * nv;
  for (size_t j = 1; j < size_t(model_.njoints); ++j, p += 12) {
    Eigen::Map<Matrix3d> R(p);
    Eigen::Map<Vector3d> t(p + 9);
    R = model_.jointPlacements[j].rotation();
    t = model_.jointPlacements[j].translation();
  }
}

// data_.oMi from the kernel's first 12 (njoints - 1) outputs; the pointer past them.
const double* Core::kernel_placements_out() {
  const double* y = kernel_->y.data();
  for (size_t j = 1; j < size_t(model_.njoints); ++j, y += 12) {
    data_.oMi[j].rotation() = Eigen::Map<const Matrix3d>(y);
    data_.oMi[j].translation() = Eigen::Map<const Vector3d>(y + 9);
  }
  return y;
}

void Core::kinematics_at(const VectorXd& q) {
  if (!kernel_) {
    pin::forwardKinematics(model_, data_, q);
    return;
  }
  kernel_inputs(q, nullptr, nullptr);
  kernel_->placements(kernel_->x.data(), kernel_->y.data());
  kernel_placements_out();
}

void Core::joint_jacobians_at(const VectorXd* q) {
  if (!kernel_) {
    if (q != nullptr) pin::computeJointJacobians(model_, data_, *q);
    else pin::computeJointJacobians(model_, data_);  // at the placements the last pass left
    return;
  }
  if (q != nullptr) kernel_inputs(*q, nullptr, nullptr);  // else x holds the last pass's q
  kernel_->jacobians(kernel_->x.data(), kernel_->y.data());
  const double* y = kernel_placements_out();
  data_.J = Eigen::Map<const Matrix6Xd>(y, 6, model_.nvExtended);
}

void Core::motion_at(const VectorXd& q, const VectorXd& v, const VectorXd& a) {
  if (!kernel_) {
    pin::forwardKinematics(model_, data_, q, v, a);
    return;
  }
  kernel_inputs(q, &v, &a);
  kernel_->motion(kernel_->x.data(), kernel_->y.data());
  const double* y = kernel_placements_out();
  for (size_t j = 1; j < size_t(model_.njoints); ++j, y += 6) data_.v[j] = pin::Motion(Eigen::Map<const Vector6d>(y));
  for (size_t j = 1; j < size_t(model_.njoints); ++j, y += 6) data_.a[j] = pin::Motion(Eigen::Map<const Vector6d>(y));
}

}  // namespace pinmech
