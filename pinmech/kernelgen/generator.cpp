// pinmech's kernel generator: Pinocchio's own kinematic passes, taped on the user's model
// and written out as C. It reads a pin.Model saved by `Model.saveToText` and writes a C
// file of three functions over one input array x = [q (nq) | v (nv) | a (nv) | P], P the
// joint placements (12 numbers a joint from joint 1: R column-major, then p), so that a
// changed dimension needs no new kernel:
//
//   pinmech_kernel_placements(x, y): forwardKinematics(q)          y = oMi (12 a joint)
//   pinmech_kernel_jacobians(x, y):  computeJointJacobians(q)      y = oMi, data.J (6 x nvExtended, column-major)
//   pinmech_kernel_motion(x, y):     forwardKinematics(q, v, a)    y = oMi, data.v, data.a (6 a joint: linear, angular)
//
// and pinmech_kernel_shape(out): the ABI number, nq, nv, nvExtended, njoints, which the core
// checks before it calls anything. The algorithms are Pinocchio's (ModelTpl on
// CppAD::AD<CppAD::cg::CG<double>>), specialised to the model's joints and tree: the kernel
// writes the same numbers into pin.Data that the generic passes write, in another order of
// the same operations. pinmech compiles this program once per machine (pinmech/solve/kernels.py)
// with the `pinmech[fast]` headers (CppAD, CppADCodeGen, Eigen) and the Pinocchio of `pin`.
#include <pinocchio/codegen/cppadcg.hpp>

#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace pin = pinocchio;
using CGD = CppAD::cg::CG<double>;
using ADCG = CppAD::AD<CGD>;
using ADModel = pin::ModelTpl<ADCG>;
using ADData = pin::DataTpl<ADCG>;
using ADVector = Eigen::Matrix<ADCG, Eigen::Dynamic, 1>;

constexpr int KERNEL_ABI = 1;

namespace {

struct Layout {
  int nq, nv, nj;
  int v0() const { return nq; }
  int a0() const { return nq + nv; }
  int p0() const { return nq + 2 * nv; }
  int size() const { return nq + 2 * nv + 12 * nj; }
};

// The tape's inputs: q (a neutral configuration's values: the tape records no branch on them),
// v, a, and the joint placements set into the model from x.
struct Inputs {
  std::vector<ADCG> x;
  ADVector q, v, a;
};

Inputs start_tape(const pin::Model& model, ADModel& ad, const Layout& L) {
  Inputs in;
  in.x.assign(size_t(L.size()), ADCG(0.0));
  const Eigen::VectorXd q0 = pin::neutral(model);
  for (int i = 0; i < L.nq; ++i) in.x[size_t(i)] = q0[i];
  for (int j = 1; j <= L.nj; ++j) {
    const pin::SE3& M = model.jointPlacements[size_t(j)];
    for (int k = 0; k < 9; ++k) in.x[size_t(L.p0() + 12 * (j - 1) + k)] = M.rotation()(k % 3, k / 3);
    for (int k = 0; k < 3; ++k) in.x[size_t(L.p0() + 12 * (j - 1) + 9 + k)] = M.translation()[k];
  }
  CppAD::Independent(in.x);
  in.q.resize(L.nq);
  in.v.resize(L.nv);
  in.a.resize(L.nv);
  for (int i = 0; i < L.nq; ++i) in.q[i] = in.x[size_t(i)];
  for (int i = 0; i < L.nv; ++i) in.v[i] = in.x[size_t(L.v0() + i)];
  for (int i = 0; i < L.nv; ++i) in.a[i] = in.x[size_t(L.a0() + i)];
  for (int j = 1; j <= L.nj; ++j) {
    Eigen::Matrix<ADCG, 3, 3> R;
    Eigen::Matrix<ADCG, 3, 1> p;
    for (int k = 0; k < 9; ++k) R(k % 3, k / 3) = in.x[size_t(L.p0() + 12 * (j - 1) + k)];
    for (int k = 0; k < 3; ++k) p[k] = in.x[size_t(L.p0() + 12 * (j - 1) + 9 + k)];
    ad.jointPlacements[size_t(j)] = pin::SE3Tpl<ADCG>(R, p);
  }
  return in;
}

void put_placements(const ADData& d, int nj, std::vector<ADCG>& y) {
  for (int j = 1; j <= nj; ++j) {
    for (int k = 0; k < 9; ++k) y.push_back(d.oMi[size_t(j)].rotation()(k % 3, k / 3));
    for (int k = 0; k < 3; ++k) y.push_back(d.oMi[size_t(j)].translation()[k]);
  }
}

void put_motions(const pin::container::aligned_vector<pin::MotionTpl<ADCG>>& m, int nj, std::vector<ADCG>& y) {
  for (int j = 1; j <= nj; ++j) {
    for (int k = 0; k < 3; ++k) y.push_back(m[size_t(j)].linear()[k]);
    for (int k = 0; k < 3; ++k) y.push_back(m[size_t(j)].angular()[k]);
  }
}

// The pass `which` (0 placements, 1 Jacobians, 2 motion) on a fresh tape, as a C function.
std::string function_of(const pin::Model& model, int which, const std::string& name, size_t& operations) {
  const Layout L{model.nq, model.nv, model.njoints - 1};
  ADModel ad = model.cast<ADCG>();
  ADData d(ad);
  Inputs in = start_tape(model, ad, L);
  std::vector<ADCG> y;
  if (which == 0) {
    pin::forwardKinematics(ad, d, in.q);
    put_placements(d, L.nj, y);
  } else if (which == 1) {
    pin::computeJointJacobians(ad, d, in.q);
    put_placements(d, L.nj, y);
    for (int c = 0; c < model.nvExtended; ++c)
      for (int r = 0; r < 6; ++r) y.push_back(d.J(r, c));
  } else {
    pin::forwardKinematics(ad, d, in.q, in.v, in.a);
    put_placements(d, L.nj, y);
    put_motions(d.v, L.nj, y);
    put_motions(d.a, L.nj, y);
  }
  CppAD::ADFun<CGD> fun(in.x, y);
  fun.optimize();
  CppAD::cg::CodeHandler<double> handler;
  std::vector<CGD> independent(size_t(L.size()));
  handler.makeVariables(independent);
  std::vector<CGD> dependent = fun.Forward(0, independent);
  CppAD::cg::LanguageC<double> language("double");
  CppAD::cg::LangCDefaultVariableNameGenerator<double> names;
  std::ostringstream body;
  handler.generateCode(body, language, dependent, names);
  operations += handler.getManagedNodesCount();
  std::ostringstream out;
  out << "void " << name << "(const double* restrict x, double* restrict y) {\n";
  out << "  double v[" << std::max<size_t>(1, handler.getTemporaryVariableCount()) << "];\n";
  out << body.str() << "}\n\n";
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: " << argv[0] << " MODEL.txt OUT.c (MODEL.txt: pinocchio.Model.saveToText)\n";
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  pin::Model model;
  try {
    model.loadFromText(argv[1]);
  } catch (const std::exception& e) {
    std::cerr << "cannot read the model " << argv[1] << ": " << e.what() << "\n";
    return 1;
  }
  std::ostringstream c;
  c << "/* pinmech kernel: Pinocchio's kinematic passes specialised to one model (generated). */\n"
    << "#include <math.h>\n\n";
  size_t operations = 0;
  c << function_of(model, 0, "pinmech_kernel_placements", operations);
  c << function_of(model, 1, "pinmech_kernel_jacobians", operations);
  c << function_of(model, 2, "pinmech_kernel_motion", operations);
  c << "void pinmech_kernel_shape(int* out) {\n  out[0] = " << KERNEL_ABI << "; out[1] = " << model.nq
    << "; out[2] = " << model.nv << "; out[3] = " << model.nvExtended << "; out[4] = " << model.njoints << ";\n}\n";
  std::ofstream file(argv[2]);
  file << c.str();
  file.close();
  if (!file) {
    std::cerr << "cannot write " << argv[2] << "\n";
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "{\"seconds\": " << seconds << ", \"operations\": " << operations << "}\n";
  return 0;
}
