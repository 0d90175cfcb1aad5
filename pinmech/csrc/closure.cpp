// pinmech's compiled core: the model, the closure rows, their Jacobians and drift, the
// assembly blocks (see core.hpp for the whole).
#include "core.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/spatial.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pinmech {

namespace {

// The pin.Model inside `model`, or a TypeError.
const pin::Model& borrowed(const nb::object& model) {
  const pin::Model* out = borrow_model(model.ptr());
  if (out == nullptr)
    throw nb::type_error("the compiled core takes a pinocchio.Model (from the installed pin)");
  return *out;
}

double det_of(const MatrixXd& A) {
  const Index n = A.rows();
  if (n == 1) return A(0, 0);
  if (n == 2) return A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return A.partialPivLu().determinant();
}

}  // namespace

Core::Core(nb::object model, const std::vector<int>& frame_ids, const std::vector<int>& cut_types,
           const std::vector<int>& cut_parent, const std::vector<int>& cut_child,
           const Eigen::Ref<const RowMatrix>& cut_axes, const Eigen::Ref<const RowMatrix>& cut_child_axes,
           const std::vector<MatrixXd>& rows6, const std::vector<MatrixXd>& full, const std::vector<int>& drv_v,
           const std::vector<int>& dep_v, const std::vector<int>& drv_q, const std::vector<int>& drv_continuous,
           const VectorXd& v_scale, const std::vector<std::vector<int>>& block_rows,
           const std::vector<std::vector<int>>& block_cols, double tol)
    : model_object_(model), model_(borrowed(model)), data_(model_), parents_(model_.parents), nq_(model_.nq),
      nv_(model_.nv), nv_extended_(model_.nvExtended), nframes_(model_.frames.size()), drv_v_(drv_v), dep_v_(dep_v),
      drv_q_(drv_q), drv_continuous_(drv_continuous), tol_(tol) {
  for (int f : frame_ids) {
    if (f < 0 || size_t(f) >= nframes_) throw std::invalid_argument("frame id " + std::to_string(f) + " not in the model");
    frames_.push_back(pin::FrameIndex(f));
  }
  const size_t ncuts = cut_types.size();
  if (cut_parent.size() != ncuts || cut_child.size() != ncuts || size_t(cut_axes.rows()) != ncuts ||
      size_t(cut_child_axes.rows()) != ncuts || rows6.size() != ncuts || full.size() != ncuts)
    throw std::invalid_argument("cut arrays of different lengths");
  Index offset = 0;
  for (size_t c = 0; c < ncuts; ++c) {
    if (rows6[c].cols() != 6 || full[c].cols() != 6 || rows6[c].rows() > 6 || full[c].rows() > 6)
      throw std::invalid_argument("closure rows must be at most 6 rows of 6 columns");
    Cut cut{cut_types[c], frames_.at(size_t(cut_parent[c])), frames_.at(size_t(cut_child[c])),
            cut_axes.row(Index(c)).transpose(), cut_child_axes.row(Index(c)).transpose(), rows6[c], full[c], offset,
            false, {}, {}, false};
    cut.ground = model_.frames[cut.parent].parentJoint == 0;
    relative_columns(cut);
    offset += cut.rows6.rows();
    cuts_.push_back(cut);
  }
  rows_ = offset;
  errors_.assign(ncuts, Vector6d::Zero());
  const Index nv = model_.nv;
  if (v_scale.size() != nv) throw std::invalid_argument("velocity scale of the wrong size");
  for (const auto* indices : {&drv_v_, &dep_v_})
    for (int v : *indices)
      if (v < 0 || v >= nv) throw std::invalid_argument("velocity index " + std::to_string(v) + " not in the model");
  for (int i : drv_q_)
    if (i < 0 || i >= model_.nq) throw std::invalid_argument("coordinate index " + std::to_string(i) + " not in the model");
  v_scale_ = v_scale;
  v_scale_inv_ = v_scale.cwiseInverse();
  dep_scale_.resize(Index(dep_v_.size()));
  for (size_t i = 0; i < dep_v_.size(); ++i) dep_scale_(Index(i)) = v_scale(dep_v_[i]);
  for (const Cut& cut : cuts_)
    for (Index v : cut.columns) {
      const auto at = std::find(dep_v_.begin(), dep_v_.end(), int(v));
      if (at != dep_v_.end()) dep_blocks_.push_back({cut.offset, cut.rows6.rows(), v, Index(at - dep_v_.begin())});
    }
  blocks_rows_ = block_rows;
  blocks_cols_ = block_cols;
  step_ = VectorXd::Zero(nv);
  zero_ = VectorXd::Zero(nv);
  tmp3_ = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nv);
  const Index ndep = Index(dep_v_.size());
  J_ = MatrixXd::Zero(rows_, nv);
  Jdep_ = MatrixXd::Zero(rows_, ndep);
  scaled_ = MatrixXd::Zero(rows_, ndep);
  for (size_t b = 0; b < blocks_rows_.size(); ++b)
    block_buffers_.push_back(MatrixXd::Zero(Index(blocks_rows_[b].size()), Index(blocks_cols_[b].size())));
  r_ = VectorXd::Zero(rows_);
  r_new_ = VectorXd::Zero(rows_);
  rhs_ = VectorXd::Zero(rows_);
  drift_ = VectorXd::Zero(rows_);
  dstep_ = VectorXd::Zero(ndep);
  q_new_ = VectorXd::Zero(model_.nq);
  predicted_ = VectorXd::Zero(nv);
  square_.set_blocks(ordered_blocks());
  square_.order(block_rows_, block_cols_);
  band_ = structural_band();
}

bool Core::same_structure() const {
  return model_.nq == nq_ && model_.nv == nv_ && model_.nvExtended == nv_extended_ &&
         model_.frames.size() == nframes_ && model_.parents == parents_;
}

void Core::check_structure() const {
  if (!same_structure())
    throw std::invalid_argument("the model's joints or frames changed since its core was built (" +
                                std::to_string(parents_.size() - 1) + " joints, " + std::to_string(nframes_) +
                                " frames then; " + std::to_string(model_.njoints - 1) + " joints, " +
                                std::to_string(model_.frames.size()) + " frames now)");
  if (kernel_stale())
    throw std::invalid_argument("the model's joints changed since its generated kernel " + kernel_->path +
                                " was loaded (a joint's type, axis, pitch or mimic ratio): it would give the old "
                                "joints' answers; set the kernel again (pinmech makes one for the new joints)");
}

// ---------------------------------------------------------------- pieces (also for tests)
VectorXd Core::residual(const VectorXd& q) {
  check_structure();
  VectorXd r(rows_);
  residual_into(q, r);
  return r;
}

// The independent closure rows at q; leaves joint placements and the cut frames'
// placements in data_ (LoopSolver._residual). The joint Jacobians at q come in the same
// pass where `jacobians` (a Jacobian will be taken here), else at the first jacobian_into
// (most residuals are the last of a Newton solve: no Jacobian is taken there).
void Core::residual_into(const VectorXd& q, VectorXd& r, bool jacobians) {
  if (jacobians) joint_jacobians_at(&q);
  else kinematics_at(q);
  joint_jacobians_ = jacobians;
  for (size_t c = 0; c < cuts_.size(); ++c) {
    const Cut& cut = cuts_[c];
    pin::updateFramePlacement(model_, data_, cut.parent);
    pin::updateFramePlacement(model_, data_, cut.child);
    errors_[c] = error6(cut);
    // lazyProduct: at most 6 x 6, coefficient by coefficient (not the general matrix-vector kernel)
    r.segment(cut.offset, cut.rows6.rows()).noalias() = cut.rows6.lazyProduct(errors_[c]);
  }
}

// Every selected row's largest |value| at the q of the last residual_into (its errors).
double Core::full_residual() const {
  double worst = 0.0;
  for (size_t c = 0; c < cuts_.size(); ++c) worst = std::max(worst, max_abs(cuts_[c].full.lazyProduct(errors_[c])));
  return worst;
}

MatrixXd Core::jacobian(bool newton) {
  check_structure();
  jacobian_into(newton);
  return J_;
}


// J_ = the stacked rows' Jacobian, Jdep_ its dependent columns at the q of the last
// residual_into; data_ then has the joint Jacobians at q too.
void Core::jacobian_into(bool newton) {
  if (!joint_jacobians_) {
    joint_jacobians_at(nullptr);  // at the q residual_into left
    joint_jacobians_ = true;
  }
  for (const Cut& cut : cuts_) relative_jacobian(cut, newton);
  // J_dep = J_'s dependent columns, copied where they are not structurally zero (a chain
  // of loops: O(loops), where the whole columns would be O(loops^2))
  for (const ColumnBlock& b : dep_blocks_) Jdep_.block(b.offset, b.dep, b.rows, 1) = J_.block(b.offset, b.v, b.rows, 1);
}

// out = J_ x, from each cut's rows' own columns (the others are exactly zero), in
// ascending column order as the dense product sums them.
void Core::rows_times(const VectorXd& x, VectorXd& out) const {
  for (const Cut& cut : cuts_) {
    auto rows = out.segment(cut.offset, cut.rows6.rows());
    rows.setZero();
    for (Index v : cut.columns) rows += J_.block(cut.offset, v, cut.rows6.rows(), 1) * x(v);
  }
}

VectorXd Core::drift(const VectorXd& q, const VectorXd& v) {
  check_structure();
  VectorXd out(rows_);
  drift_into(q, v, out);
  return out;
}

void Core::drift_into(const VectorXd& q, const VectorXd& v, VectorXd& out) {
  motion_at(q, v, zero_);
  joint_jacobians_ = false;  // data_.J is computed again from these placements where asked
  for (const Cut& cut : cuts_) {
    pin::updateFramePlacement(model_, data_, cut.parent);  // at this q, whatever the last call's was
    pin::updateFramePlacement(model_, data_, cut.child);
    const Vector6d e = relative_acceleration6(frame_motion(cut.parent, cut.ground), frame_motion(cut.child, false));
    out.segment(cut.offset, cut.rows6.rows()).noalias() = cut.rows6.lazyProduct(e);
  }
}

// A frame's world motion from data_ after forwardKinematics(q, v, a) and its placement
// (at rest where `ground`: a frame of the ground has no velocity or acceleration).
FrameMotion<double> Core::frame_motion(pin::FrameIndex frame, bool ground) const {
  FrameMotion<double> out;
  out.x = data_.oMf[frame].translation();
  out.R = data_.oMf[frame].rotation();
  if (ground) {
    out.v.setZero();
    out.w.setZero();
    out.acc.setZero();
    out.alpha.setZero();
    return out;
  }
  const pin::Motion V = pin::getFrameVelocity(model_, data_, frame, pin::LOCAL_WORLD_ALIGNED);
  const pin::Motion A = pin::getFrameClassicalAcceleration(model_, data_, frame, pin::LOCAL_WORLD_ALIGNED);
  out.v = V.linear();
  out.w = V.angular();
  out.acc = A.linear();
  out.alpha = A.angular();
  return out;
}

RowMatrix Core::errors6(const VectorXd& q) {
  check_structure();
  residual_into(q, r_);
  RowMatrix out(Index(cuts_.size()), 6);
  for (size_t c = 0; c < cuts_.size(); ++c) out.row(Index(c)) = error6(cuts_[c]).transpose();
  return out;
}

RowMatrix Core::translation_rows() const {
  RowMatrix out(rows_, 3);
  for (const Cut& cut : cuts_)
    out.middleRows(cut.offset, cut.rows6.rows()).noalias() =
        cut.rows6.leftCols<3>() * data_.oMf[cut.parent].rotation().transpose();
  return out;
}

namespace {

// The frames' motions of a FrameMotion in rows (x, v, w, acc, alpha, then R's three rows),
// each moved by i h times its change (dx, dv, dw, dacc, dalpha; R by [dtheta]x R).
FrameMotion<std::complex<double>> stepped(const Eigen::Ref<const RowMatrix>& M, const Eigen::Ref<const RowMatrix>& dM,
                                          double h) {
  using C = std::complex<double>;
  const std::complex<double> ih(0.0, h);
  auto row = [&](Index i) -> Eigen::Matrix<C, 3, 1> {
    return M.row(i).transpose().cast<C>() + ih * dM.row(i).transpose().cast<C>();
  };
  FrameMotion<C> out;
  out.x = row(0);
  out.v = row(1);
  out.w = row(2);
  out.acc = row(3);
  out.alpha = row(4);
  const Matrix3d R = M.middleRows<3>(5);
  out.R = R.cast<C>() + ih * (pin::skew(Vector3d(dM.row(5).transpose())) * R).cast<C>();
  return out;
}

}  // namespace

VectorXd cut_rows_change(const Eigen::Ref<const RowMatrix>& rows6, int order, const Eigen::Ref<const RowMatrix>& P,
                         const Eigen::Ref<const RowMatrix>& C, const Eigen::Ref<const RowMatrix>& dP,
                         const Eigen::Ref<const RowMatrix>& dC) {
  if (rows6.cols() != 6 || P.rows() != 8 || C.rows() != 8 || dP.rows() != 6 || dC.rows() != 6 || P.cols() != 3 ||
      C.cols() != 3 || dP.cols() != 3 || dC.cols() != 3)
    throw std::invalid_argument("cut_rows_change: rows6 (k, 6), P and C (8, 3), dP and dC (6, 3)");
  if (order != 1 && order != 2) throw std::invalid_argument("cut_rows_change: order 1 (velocity) or 2 (acceleration)");
  // The complex step: the rows are polynomials in the motions, so Im f(x + i h dx) / h is
  // their derivative along dx to rounding (the next term is h^2 smaller), with no
  // difference of nearby values; h shrunk with the changes' size.
  const double h = 1e-20 / std::max({dP.cwiseAbs().maxCoeff(), dC.cwiseAbs().maxCoeff(), 1.0});
  const auto Ps = stepped(P, dP, h), Cs = stepped(C, dC, h);
  const Eigen::Matrix<std::complex<double>, 6, 1> e =
      order == 1 ? relative_velocity6(Ps, Cs) : relative_acceleration6(Ps, Cs);
  return rows6 * (e.imag() / h);
}

std::vector<int> Core::signs(const MatrixXd& J_dep) {
  std::vector<int> out;
  signs_into(J_dep, out);
  return out;
}

// The sign of each block's determinant (branches.AssemblyStructure.signs).
void Core::signs_into(const MatrixXd& J_dep, std::vector<int>& out) {
  out.resize(blocks_rows_.size());
  for (size_t b = 0; b < blocks_rows_.size(); ++b) {
    const auto &rows = blocks_rows_[b], &cols = blocks_cols_[b];
    MatrixXd& B = block_buffers_[b];
    for (size_t i = 0; i < rows.size(); ++i)
      for (size_t j = 0; j < cols.size(); ++j) B(Index(i), Index(j)) = J_dep(rows[i], cols[j]);
    const double det = det_of(B);
    out[b] = det > 0 ? 1 : det < 0 ? -1 : 0;
  }
}

Vector6d Core::error6(const Cut& cut) const {
  const pin::SE3 &MP = data_.oMf[cut.parent], &MC = data_.oMf[cut.child];
  Vector6d e;
  e.head<3>() = MP.rotation().transpose() * (MC.translation() - MP.translation());
  if (cut.type == SPHERICAL_CUT) {
    e.tail<3>().setZero();
  } else {
    const Matrix3d R_rel = MP.rotation().transpose() * MC.rotation();
    if (cut.type == REVOLUTE)
      e.tail<3>() = cut.axis.cross(R_rel * cut.child_axis);
    else
      e.tail<3>() = pin::log3(R_rel);
  }
  return e;
}


// The columns of the cut's relative Jacobian that can be nonzero (Cut::child_cols): each
// joint's data.J columns (nvExtended of them) with the velocity column they add to, from
// Pinocchio's own map (a mimic joint's is its leader's).
void Core::relative_columns(Cut& cut) const {
  const auto& P = model_.supports[model_.frames[cut.parent].parentJoint];
  const auto& C = model_.supports[model_.frames[cut.child].parentJoint];
  auto add = [this](std::vector<JointColumn>& cols, const std::vector<pin::JointIndex>& from,
                    const std::vector<pin::JointIndex>& other) {
    for (pin::JointIndex j : from) {
      if (j == 0 || std::find(other.begin(), other.end(), j) != other.end()) continue;
      for (int k = 0; k < model_.nvExtendeds[j]; ++k) {
        const Index extended = Index(model_.idx_vExtendeds[j] + k);
        cols.push_back({extended, Index(data_.idx_vExtended_to_idx_v_fromRow[size_t(extended)])});
      }
    }
  };
  add(cut.child_cols, C, P);
  add(cut.parent_cols, P, C);
  std::vector<Index> seen;
  for (const auto* cols : {&cut.child_cols, &cut.parent_cols})
    for (const JointColumn& c : *cols) {
      if (std::find(seen.begin(), seen.end(), c.v) != seen.end()) cut.shared_columns = true;
      else seen.push_back(c.v);
    }
  std::sort(seen.begin(), seen.end());
  cut.columns = seen;
}

// Rows offset .. offset + k of J_ = the cut's rows6 times its (6, nv) map from joint
// velocities to (r_dot, w) of C in P; with `newton`, orientation rows carry the
// derivative of the error measure instead (the exact derivative of the residual). Columns come
// from data_.J (world axes, at the origin: pin::getFrameJacobian's source), only those
// of Cut::child_cols and parent_cols; J_'s other columns of these rows stay zero.
void Core::relative_jacobian(const Cut& cut, bool newton) {
  const pin::SE3 &MP = data_.oMf[cut.parent], &MC = data_.oMf[cut.child];
  const Matrix3d RT = MP.rotation().transpose();
  const Vector3d &pP = MP.translation(), &pC = MC.translation();
  const Vector3d delta = pC - pP;
  Matrix3d M = Matrix3d::Identity();
  if (newton && cut.type != SPHERICAL_CUT) {
    const Matrix3d R_rel = RT * MC.rotation();
    if (cut.type == REVOLUTE) {
      M = -pin::skew(cut.axis) * pin::skew(Vector3d(R_rel * cut.child_axis));
    } else {
      Matrix3d Jlog;
      pin::Jlog3(R_rel, Jlog);
      M = Jlog * R_rel.transpose();
    }
  }
  const Matrix3d MRT = M * RT;
  const Index k = cut.rows6.rows();
  if (cut.shared_columns)  // several data.J columns add to one velocity column: sum from zero
    for (const auto* cols : {&cut.child_cols, &cut.parent_cols})
      for (const JointColumn& c : *cols) J_.block(cut.offset, c.v, k, 1).setZero();
  Vector6d e;
  for (const JointColumn& c : cut.child_cols) {  // C's frame velocity at C, in P's axes
    const Vector3d w = data_.J.col(c.extended).tail<3>();
    e.head<3>().noalias() = RT * (data_.J.col(c.extended).head<3>() + w.cross(pC));
    e.tail<3>().noalias() = MRT * w;
    if (cut.shared_columns) J_.block(cut.offset, c.v, k, 1).noalias() += cut.rows6.lazyProduct(e);
    else J_.block(cut.offset, c.v, k, 1).noalias() = cut.rows6.lazyProduct(e);
  }
  for (const JointColumn& c : cut.parent_cols) {  // minus P's frame velocity at P, and P turning delta
    const Vector3d w = data_.J.col(c.extended).tail<3>();
    const Vector3d v = data_.J.col(c.extended).head<3>() + w.cross(pP);
    e.head<3>().noalias() = RT * (delta.cross(w) - v);
    e.tail<3>().noalias() = -(MRT * w);
    if (cut.shared_columns) J_.block(cut.offset, c.v, k, 1).noalias() += cut.rows6.lazyProduct(e);
    else J_.block(cut.offset, c.v, k, 1).noalias() = cut.rows6.lazyProduct(e);
  }
}

// The assembly blocks (branches.AssemblyStructure: the irreducible diagonal blocks of
// J_dep's block-triangular form) in an order for forward substitution, each with the
// columns of earlier blocks its rows touch (its cut's support columns: J_dep is exactly
// zero elsewhere). None (the whole matrix at once) where there is one block, where the
// blocks do not partition a square J_dep into square blocks, or where no order has every
// block touch only earlier ones.
std::vector<DiagonalBlock> Core::ordered_blocks() const {
  const Index n = Index(dep_v_.size());
  const size_t count = blocks_rows_.size();
  if (count < 2 || rows_ != n || blocks_cols_.size() != count) return {};
  std::vector<int> row_block(size_t(n), -1), col_block(size_t(n), -1);
  for (size_t b = 0; b < count; ++b) {
    if (blocks_rows_[b].size() != blocks_cols_[b].size() || blocks_rows_[b].empty()) return {};
    for (int r : blocks_rows_[b]) {
      if (r < 0 || r >= n || row_block[size_t(r)] != -1) return {};
      row_block[size_t(r)] = int(b);
    }
    for (int c : blocks_cols_[b]) {
      if (c < 0 || c >= n || col_block[size_t(c)] != -1) return {};
      col_block[size_t(c)] = int(b);
    }
  }
  std::vector<Index> dep_col(size_t(model_.nv), -1);
  for (size_t i = 0; i < dep_v_.size(); ++i) dep_col[size_t(dep_v_[i])] = Index(i);
  std::vector<std::vector<Index>> coupling(count);
  std::vector<std::vector<char>> needs(count, std::vector<char>(count, 0));
  for (const Cut& cut : cuts_) {
    for (Index r = cut.offset; r < cut.offset + cut.rows6.rows(); ++r) {
      const int b = row_block[size_t(r)];
      for (const auto* cols : {&cut.child_cols, &cut.parent_cols})
        for (const JointColumn& column : *cols) {
          const Index c = dep_col[size_t(column.v)];
          if (c < 0 || col_block[size_t(c)] == b) continue;
          needs[size_t(b)][size_t(col_block[size_t(c)])] = 1;
          if (std::find(coupling[size_t(b)].begin(), coupling[size_t(b)].end(), c) == coupling[size_t(b)].end())
            coupling[size_t(b)].push_back(c);
        }
    }
  }
  // Columns later blocks lean on go last in their own block: in block order J_dep is then
  // a narrower band (a chain of loops: 2 below the diagonal, not 3), which the condition
  // number's rotations are quicker on.
  std::vector<char> exported(size_t(n), 0);
  for (const auto& cols : coupling)
    for (Index c : cols) exported[size_t(c)] = 1;
  std::vector<DiagonalBlock> out;
  std::vector<char> placed(count, 0);
  while (out.size() < count) {  // a block whose needs are all placed, first by index
    size_t next = count;
    for (size_t b = 0; b < count && next == count; ++b) {
      if (placed[b]) continue;
      bool ready = true;
      for (size_t c = 0; c < count; ++c) ready = ready && (!needs[b][c] || placed[c]);
      if (ready) next = b;
    }
    if (next == count) return {};  // a cycle: not block-triangular in these blocks
    placed[next] = 1;
    DiagonalBlock block;
    block.rows.assign(blocks_rows_[next].begin(), blocks_rows_[next].end());
    block.cols.assign(blocks_cols_[next].begin(), blocks_cols_[next].end());
    std::stable_partition(block.cols.begin(), block.cols.end(), [&](Index c) { return !exported[size_t(c)]; });
    block.coupling = coupling[next];
    std::sort(block.coupling.begin(), block.coupling.end());
    const Index m = Index(block.rows.size());
    block.M = MatrixXd::Zero(m, m);
    block.rhs = VectorXd::Zero(m);
    block.x = VectorXd::Zero(m);
    out.push_back(std::move(block));
  }
  return out;
}

// J_dep's band in block order (block_rows_, block_cols_): the farthest below and above
// the diagonal any row's support columns reach (each cut's rows are exactly zero outside
// its child's and parent's columns), known at build, so condition_of need not scan for it
// at every pose. None where there is no block order.
std::optional<Band> Core::structural_band() const {
  if (block_rows_.empty()) return std::nullopt;
  const Index n = Index(block_cols_.size());
  std::vector<Index> position_of_v(size_t(model_.nv), -1), position_of_row(size_t(rows_), -1);
  for (Index p = 0; p < n; ++p) position_of_v[size_t(dep_v_[size_t(block_cols_[size_t(p)])])] = p;
  for (Index p = 0; p < Index(block_rows_.size()); ++p) position_of_row[size_t(block_rows_[size_t(p)])] = p;
  Band band{0, 0, block_rows_, block_cols_};
  for (const Cut& cut : cuts_)
    for (Index r = cut.offset; r < cut.offset + cut.rows6.rows(); ++r) {
      const Index i = position_of_row[size_t(r)];
      if (i < 0) return std::nullopt;
      for (const auto* cols : {&cut.child_cols, &cut.parent_cols})
        for (const JointColumn& column : *cols) {
          const Index j = position_of_v[size_t(column.v)];
          if (j < 0) continue;  // a driver's column
          band.lower = std::max(band.lower, i - j);
          band.upper = std::max(band.upper, j - i);
        }
    }
  return band;
}

}  // namespace pinmech
