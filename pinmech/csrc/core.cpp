// pinmech's compiled core: a sweep of one driver followed pose by pose, in C++ on Pinocchio.
//
// It computes what pinmech/solve_loops.py (closure rows, corrector, rates) and
// pinmech/continuation.py (predictor, trust region, tangent turn, assembly signature)
// compute, with the same rules and constants, for the regular steps of a sweep: where a
// step needs anything more (a signature change, a pivot below PIVOT_BELOW, a singular or
// overflowing pose, a pose worse conditioned than max_condition) it stops and hands the
// pose back to the Python path, which names what happened. pinmech/core.py builds it from
// a LoopSolver; tests/test_core.py checks every number against the Python path and the
// closed forms.
//
// The model is rebuilt here from its joints and frames (types, parents, placements, axes),
// so only Pinocchio's headers are needed: nothing is linked against the pin wheel's
// libraries, and the numbers do not depend on which pin version is installed.

#include <nanobind/nanobind.h>
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <pinocchio/multibody.hpp>
#include <pinocchio/spatial.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Householder>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

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

namespace {

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
constexpr int LINE_SEARCH_HALVINGS = 30;

enum JointType {
  RX, RY, RZ, R_AXIS, RUBX, RUBY, RUBZ, RUB_AXIS, PX, PY, PZ, P_AXIS, SPHERICAL, PLANAR, FREE, TRANSLATION
};
enum CutType { REVOLUTE, PRISMATIC, SPHERICAL_CUT, FIXED };

// Why a sweep stopped before its last pose (the Python path then takes that pose).
enum Stop { DONE = 0, NEEDS_PIVOT = 1, SIGNATURE_CHANGED = 2, CONDITION = 3, NOT_FINITE = 4 };

pin::SE3 placement_of(const double* row) {  // 12 numbers: R row by row, then p
  Matrix3d R;
  R << row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7], row[8];
  return pin::SE3(R, Vector3d(row[9], row[10], row[11]));
}

pin::JointModel joint_model(int type, const Vector3d& axis) {
  switch (type) {
    case RX: return pin::JointModelRX();
    case RY: return pin::JointModelRY();
    case RZ: return pin::JointModelRZ();
    case R_AXIS: return pin::JointModelRevoluteUnaligned(axis);
    case RUBX: return pin::JointModelRUBX();
    case RUBY: return pin::JointModelRUBY();
    case RUBZ: return pin::JointModelRUBZ();
    case RUB_AXIS: return pin::JointModelRevoluteUnboundedUnaligned(axis);
    case PX: return pin::JointModelPX();
    case PY: return pin::JointModelPY();
    case PZ: return pin::JointModelPZ();
    case P_AXIS: return pin::JointModelPrismaticUnaligned(axis);
    case SPHERICAL: return pin::JointModelSpherical();
    case PLANAR: return pin::JointModelPlanar();
    case FREE: return pin::JointModelFreeFlyer();
    case TRANSLATION: return pin::JointModelTranslation();
  }
  throw std::invalid_argument("unknown joint type code " + std::to_string(type));
}

// Steps between two looks at Python's signal handlers in a long loop run without the GIL.
constexpr long SIGNAL_EVERY = 4096;

// Run Python's signal handlers (Ctrl-C, SIGTERM: pinmech's raise Interrupted) from a loop
// that released the GIL, and leave the loop with the exception they raised.
void check_signals() {
  nb::gil_scoped_acquire acquire;
  if (PyErr_CheckSignals() != 0) throw nb::python_error();
}

double max_abs(const Eigen::Ref<const VectorXd>& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

// A x = b for a small square A, as solve_loops._solve_square: closed forms up to 2x2, LU
// with partial pivoting above; NaN where A is exactly singular. Factored once for several
// right-hand sides; the LU's buffers are reused, so a pose allocates nothing.
class DenseSolve {
 public:
  void factor(const MatrixXd& A) {  // A must stay as it is until the last solve
    A_ = &A;
    const Index n = A.rows();
    if (n == 1) {
      singular_ = A(0, 0) == 0.0;
    } else if (n == 2) {
      det_ = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
      singular_ = det_ == 0.0;
    } else if (n >= 3) {
      lu_.compute(A);
      singular_ = lu_.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0;
    } else {
      singular_ = false;
    }
  }

  // Factored with an exact zero pivot (a zero determinant up to 2x2).
  bool singular() const { return singular_; }

  void solve(const VectorXd& b, VectorXd& x) const {
    const MatrixXd& A = *A_;
    const Index n = A.rows();
    x.resize(n);
    if (singular_) {
      x.setConstant(NAN);
    } else if (n == 1) {
      x(0) = b(0) / A(0, 0);
    } else if (n == 2) {
      x << (A(1, 1) * b(0) - A(0, 1) * b(1)) / det_, (A(0, 0) * b(1) - A(1, 0) * b(0)) / det_;
    } else if (n > 2) {
      x = lu_.solve(b);
    }
  }

 private:
  const MatrixXd* A_ = nullptr;
  Eigen::PartialPivLU<MatrixXd> lu_;
  double det_ = 0.0;  // 2x2
  bool singular_ = false;
};

// One diagonal block of the dependent Jacobian's block-triangular form: its rows and
// columns, the columns of earlier blocks its rows touch, and buffers.
struct DiagonalBlock {
  std::vector<Index> rows, cols, coupling;
  MatrixXd M;
  DenseSolve dense;
  VectorXd rhs, x;
};

// A x = b for the square dependent Jacobian: by forward substitution over the diagonal
// blocks of its block-triangular form where it has several (Core::ordered_blocks: each
// block's rows touch only its own and earlier blocks' columns), each block solved as
// DenseSolve, so a chain of k loops costs k small factorizations, not one of size 2k;
// whole where it is one block. A block-triangular A is singular exactly where one of its
// diagonal blocks is: then NaN everywhere, as DenseSolve gives for a singular A.
class SquareSolve {
 public:
  void set_blocks(std::vector<DiagonalBlock> blocks) { blocks_ = std::move(blocks); }
  size_t blocks() const { return blocks_.size(); }

  // A's rows and columns block by block, in the blocks' order (empty: one block). In this
  // order a chain of loops is a band matrix (each loop's rows touch its own columns and
  // the previous loop's output).
  void order(std::vector<Index>& rows, std::vector<Index>& cols) const {
    rows.clear();
    cols.clear();
    for (const DiagonalBlock& b : blocks_) {
      rows.insert(rows.end(), b.rows.begin(), b.rows.end());
      cols.insert(cols.end(), b.cols.begin(), b.cols.end());
    }
  }

  void factor(const MatrixXd& A) {  // A must stay as it is until the last solve
    A_ = &A;
    if (blocks_.empty()) {
      whole_.factor(A);
      singular_ = whole_.singular();
      return;
    }
    singular_ = false;
    for (DiagonalBlock& b : blocks_) {
      for (size_t i = 0; i < b.rows.size(); ++i)
        for (size_t j = 0; j < b.cols.size(); ++j) b.M(Index(i), Index(j)) = A(b.rows[i], b.cols[j]);
      b.dense.factor(b.M);
      singular_ = singular_ || b.dense.singular();
    }
  }

  // Factored with an exact zero pivot in A (or in a diagonal block of it).
  bool singular() const { return singular_; }

  void solve(const VectorXd& rhs, VectorXd& x) {
    if (blocks_.empty()) {
      whole_.solve(rhs, x);
      return;
    }
    const MatrixXd& A = *A_;
    x.resize(A.cols());
    if (singular_) {
      x.setConstant(NAN);
      return;
    }
    for (DiagonalBlock& b : blocks_) {
      for (size_t i = 0; i < b.rows.size(); ++i) {
        double s = rhs(b.rows[i]);
        for (Index c : b.coupling) s -= A(b.rows[i], c) * x(c);
        b.rhs(Index(i)) = s;
      }
      b.dense.solve(b.rhs, b.x);
      for (size_t j = 0; j < b.cols.size(); ++j) x(b.cols[j]) = b.x(Index(j));
    }
  }

 private:
  const MatrixXd* A_ = nullptr;
  std::vector<DiagonalBlock> blocks_;
  DenseSolve whole_;
  bool singular_ = false;
};

// ---------------------------------------------------------------- condition numbers
// Above 3x3 the singular values come from a bidiagonalization B = U^T A V: plane
// rotations that keep the band for a band matrix (band_bidiagonalize), Householder
// reflections otherwise (bidiagonalize). Both are backward stable (B's singular values are
// those of A + E, |E| <= c n eps |A|: sigma_max exact to rounding, sigma_min to about eps
// x condition, as an SVD gives them). The extreme singular values of B are then
// eigenvalues of its Golub-Kahan matrix: the 2n x 2n symmetric tridiagonal with zero
// diagonal and off-diagonals d0, e0, d1, e1, ..., d(n-1), whose eigenvalues are +-sigma_i.
// Counting its eigenvalues below x (Sturm count; exact for a matrix within a few eps
// relative of it) brackets a singular value; Laguerre's method on det(T - x I) finds it in
// a few passes (cubic convergence, monotone for a polynomial with real roots), and two
// counts certify the result to 4 (2n) eps relative. Where Laguerre has not converged (a
// cluster of singular values acts as a multiple root), plain bisection on the counts finds
// it. Cost and accuracy against numpy's SVD: scripts/condition_time.py (README);
// tests/test_core.py checks against numpy's SVD.

constexpr double EPS = std::numeric_limits<double>::epsilon();
constexpr double PIVMIN = std::numeric_limits<double>::min();
constexpr int LAGUERRE_PASSES = 20;

// Work buffers of condition_of (sized on first use).
struct ConditionWork {
  MatrixXd B;
  VectorXd d, e, tmp, beta;  // B's diagonal and superdiagonal; squared Golub-Kahan off-diagonals
};

// Upper bidiagonalization in place by Householder reflections from both sides (values only:
// the reflections are not kept), as Eigen's upperbidiagonalization_inplace_unblocked.
void bidiagonalize(ConditionWork& w) {
  MatrixXd& B = w.B;
  const Index n = B.rows();
  w.d.resize(n);
  w.e.resize(n - 1);
  w.tmp.resize(n);
  for (Index k = 0;; ++k) {
    const Index rows = n - k, cols = n - k - 1;
    double tau, beta;
    B.col(k).tail(rows).makeHouseholderInPlace(tau, beta);
    w.d(k) = beta;
    B.bottomRightCorner(rows, cols).applyHouseholderOnTheLeft(B.col(k).tail(rows - 1), tau, w.tmp.data());
    if (k == n - 1) break;
    B.row(k).tail(cols).makeHouseholderInPlace(tau, beta);
    w.e(k) = beta;
    B.bottomRightCorner(rows - 1, cols)
        .applyHouseholderOnTheRight(B.row(k).tail(cols - 1).transpose(), tau, w.tmp.data());
  }
}

// A plane rotation [c s; -s c] taking (a, b) to (r, 0).
struct Rotation {
  double c, s;
};

Rotation rotation(double a, double b) {
  if (b == 0.0) return {1.0, 0.0};
  double r = std::sqrt(a * a + b * b);
  if (!(r > 1e-150 && r < 1e150)) r = std::hypot(a, b);  // no under- or overflow in the squares
  const double inv = 1.0 / r;
  return {a * inv, b * inv};
}

void rotate_rows(MatrixXd& R, Index p, Index q, Index from, Index to, Rotation g) {
  for (Index t = from; t <= to; ++t) {
    const double x = R(p, t), y = R(q, t);
    R(p, t) = g.c * x + g.s * y;
    R(q, t) = g.c * y - g.s * x;
  }
}

void rotate_columns(MatrixXd& R, Index p, Index q, Index from, Index to, Rotation g) {
  double *cp = &R(0, p), *cq = &R(0, q);
  for (Index t = from; t <= to; ++t) {
    const double x = cp[t], y = cq[t];
    cp[t] = g.c * x + g.s * y;
    cq[t] = g.c * y - g.s * x;
  }
}

// Upper bidiagonalization of a band matrix (nonzeros at most kl below and ku above the
// diagonal) in place by plane rotations, which keep the band: a QR clears the lower band
// (R then has upper bandwidth w = kl + ku), then each row's entries beyond the
// superdiagonal are cleared from the outside in by a column rotation, and the bulge this
// leaves below the diagonal is chased down the band, w rows a step, by alternating row and
// column rotations (as LAPACK's dgbbrd). About n^2 w rotations against the dense
// reflections' 8 n^3 / 3 flops; condition_of takes them where the band is narrow enough
// for that to pay (scripts/condition_time.py times both).
void band_bidiagonalize(ConditionWork& w, Index kl, Index ku) {
  MatrixXd& R = w.B;
  const Index n = R.rows(), width = kl + ku;
  for (Index j = 0; j + 1 < n; ++j)
    for (Index i = std::min(n - 1, j + kl); i > j; --i) {
      if (R(i, j) == 0.0) continue;
      rotate_rows(R, i - 1, i, j, std::min(n - 1, i + width), rotation(R(i - 1, j), R(i, j)));
      R(i, j) = 0.0;
    }
  for (Index k = 0; k + 2 < n && width >= 2; ++k)
    for (Index j = std::min(n - 1, k + width); j >= k + 2; --j) {
      if (R(k, j) == 0.0) continue;
      rotate_columns(R, j - 1, j, k, j, rotation(R(k, j - 1), R(k, j)));
      R(k, j) = 0.0;
      for (Index r = j;;) {  // the bulge at (r, r - 1), below the diagonal
        if (R(r, r - 1) != 0.0) {
          rotate_rows(R, r - 1, r, r - 1, std::min(n - 1, r + width), rotation(R(r - 1, r - 1), R(r, r - 1)));
          R(r, r - 1) = 0.0;
        }
        const Index c = r + width;  // the bulge at (r - 1, c), beyond the band
        if (c > n - 1 || R(r - 1, c) == 0.0) break;
        rotate_columns(R, c - 1, c, r - 1, c, rotation(R(r - 1, c - 1), R(r - 1, c)));
        R(r - 1, c) = 0.0;
        r = c;
      }
    }
  w.d.resize(n);
  w.e.resize(n - 1);
  for (Index i = 0; i < n; ++i) {
    w.d(i) = R(i, i);
    if (i + 1 < n) w.e(i) = R(i, i + 1);
  }
}

// Eigenvalues of the Golub-Kahan matrix (squared off-diagonals beta) below each of K
// values x: K independent recurrences in one loop, so their divisions overlap.
template <int K>
void counts_below(const VectorXd& beta, const double* x, int* count) {
  double t[K];
  for (int k = 0; k < K; ++k) {
    t[k] = std::abs(x[k]) <= PIVMIN ? -PIVMIN : -x[k];
    count[k] = t[k] < 0;
  }
  for (Index j = 0; j < beta.size(); ++j) {
    const double b = beta(j);
    for (int k = 0; k < K; ++k) {
      double u = -x[k] - b / t[k];
      if (std::abs(u) <= PIVMIN) u = -PIVMIN;
      t[k] = u;
      count[k] += u < 0;
    }
  }
}

int count_below(const VectorXd& beta, double x) {
  int count;
  counts_below<1>(beta, &x, &count);
  return count;
}

// One Laguerre step for det(T - x I) = prod t_j (the pivots of the Sturm count, with their
// first and second derivatives in x): G = p'/p, H = -(ln p)''. `right`: the step towards
// the next root above x, else the one below. K steps at once, as counts_below.
template <int K>
void laguerre_steps(const VectorXd& beta, const double* x, const bool* right, double* next) {
  double t[K], t1[K], t2[K], r[K], G[K], H[K];
  for (int k = 0; k < K; ++k) {
    t[k] = std::abs(x[k]) <= PIVMIN ? -PIVMIN : -x[k];
    t1[k] = -1.0;
    t2[k] = 0.0;
    r[k] = 1.0 / t[k];
    G[k] = t1[k] * r[k];
    H[k] = G[k] * G[k];
  }
  for (Index j = 0; j < beta.size(); ++j) {
    const double b = beta(j);
    for (int k = 0; k < K; ++k) {
      const double rr = r[k] * r[k];
      t2[k] = b * rr * (t2[k] - 2.0 * r[k] * t1[k] * t1[k]);
      t1[k] = -1.0 + b * rr * t1[k];
      double u = -x[k] - b * r[k];
      if (std::abs(u) <= PIVMIN) u = -PIVMIN;
      t[k] = u;
      r[k] = 1.0 / u;
      const double v = t1[k] * r[k];
      G[k] += v;
      H[k] += v * v - t2[k] * r[k];
    }
  }
  const double m = double(beta.size() + 1);
  for (int k = 0; k < K; ++k) {
    const double disc = std::sqrt(std::max(0.0, (m - 1.0) * (m * H[k] - G[k] * G[k])));
    next[k] = x[k] - m / (right[k] ? G[k] - disc : G[k] + disc);
  }
}

// A search for the eigenvalue with `index` eigenvalues below it, from x below it (`right`)
// or above, within the bracket lo < it <= hi (bisection's start where Laguerre fails).
struct EigenvalueSearch {
  int index;
  double x;
  bool right;
  double lo, hi;
  bool moving = true, converged = false;
};

// Both searches at once (sigma_max and sigma_min): Laguerre passes while either moves, two
// counts on either side of each result to certify it to 4 (2n) eps relative, and
// bisection on the counts for a search Laguerre did not bring there (it left the bracket,
// or a cluster of eigenvalues slowed it down).
void find_eigenvalues(const VectorXd& beta, EigenvalueSearch (&searches)[2], double (&found)[2]) {
  const double delta = 4.0 * double(beta.size() + 1) * EPS;
  for (int pass = 0; pass < LAGUERRE_PASSES; ++pass) {
    EigenvalueSearch* live[2];
    int count = 0;
    for (EigenvalueSearch& s : searches)
      if (s.moving) live[count++] = &s;
    if (count == 0) break;
    double x[2], next[2];
    bool right[2];
    for (int k = 0; k < count; ++k) {
      x[k] = live[k]->x;
      right[k] = live[k]->right;
    }
    if (count == 2) laguerre_steps<2>(beta, x, right, next);
    else laguerre_steps<1>(beta, x, right, next);
    for (int k = 0; k < count; ++k) {
      EigenvalueSearch& s = *live[k];
      if (!(next[k] > s.lo && next[k] <= s.hi)) {  // left the bracket (or NaN): bisect
        s.moving = false;
        continue;
      }
      s.converged = std::abs(next[k] - s.x) <= 2.0 * EPS * next[k];
      s.moving = !s.converged;
      s.x = next[k];
    }
  }
  const double sides[4] = {searches[0].x * (1.0 - delta), searches[0].x * (1.0 + delta),
                           searches[1].x * (1.0 - delta), searches[1].x * (1.0 + delta)};
  int counts[4];
  counts_below<4>(beta, sides, counts);
  for (int i = 0; i < 2; ++i) {
    EigenvalueSearch& s = searches[i];
    if (s.converged && counts[2 * i] == s.index && counts[2 * i + 1] > s.index) {
      found[i] = s.x;
      continue;
    }
    double lo = s.lo, hi = s.hi;
    while (hi - lo > 2.0 * EPS * hi && hi > PIVMIN) {
      const double mid = lo > 0.0 && hi > 4.0 * lo ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
      (count_below(beta, mid) > s.index ? hi : lo) = mid;
    }
    found[i] = 0.5 * (lo + hi);
  }
}

// 2-norm condition number and smallest singular value, as solve_loops._condition: closed
// forms up to 2x2, bidiagonalization from 3x3 up (Eigen's closed-form 3x3 eigenvalues of
// A^T A lost 1e-9 of the condition number at a repeated singular value, where rounding
// allows 1e-14: tests/test_core.py found it).
// `singular`: the caller's factorization of A (which it also solves with) met an exact zero
// pivot (used above 3x3).
std::pair<double, double> condition_of(const MatrixXd& A, bool singular, ConditionWork& work) {
  const Index n = A.rows();
  if (n == 0) return {1.0, 1.0};
  if (n == 1) {
    const double s = std::abs(A(0, 0));
    return {s > 0 ? 1.0 : INFINITY, s};
  }
  if (n == 2) {
    // sigma_max = |(a+e, c-d)|/2 + |(a-e, c+d)|/2, a sum of two non-negative terms (no
    // cancellation, where sqrt(frob^4 - 4 det^2) lost 1e-12 near condition 1); then
    // sigma_min = |det| / sigma_max.
    const double a = A(0, 0), c = A(0, 1), d = A(1, 0), e = A(1, 1);
    const double s_max = 0.5 * (std::hypot(a + e, c - d) + std::hypot(a - e, c + d));
    const double det = std::abs(a * e - c * d);
    const double s_min = s_max > 0 ? det / s_max : 0.0;
    return {det > 0 ? s_max * s_max / det : INFINITY, s_min};
  }
  if (singular) return {INFINITY, 0.0};
  const double largest_entry = A.cwiseAbs().maxCoeff();
  if (!std::isfinite(largest_entry)) return {INFINITY, 0.0};
  int exponent = 0;  // B = A / 2^exponent, its largest entry in [1/2, 1): exact, and no over- or underflow
  std::frexp(largest_entry, &exponent);
  work.B = A * std::ldexp(1.0, -exponent);
  // The band of exact zeros (J_dep's structure: a chain of loops has kl = 2, ku = 1); the
  // rotations where they are cheaper than the reflections (measured crossover).
  Index kl = 0, ku = 0;
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i)
      if (work.B(i, j) != 0.0) {
        kl = std::max(kl, i - j);
        ku = std::max(ku, j - i);
      }
  if (11 * (kl + ku) <= 2 * n + 16) band_bidiagonalize(work, kl, ku);
  else bidiagonalize(work);
  const VectorXd &d = work.d, &e = work.e;
  VectorXd& beta = work.beta;
  beta.resize(2 * n - 1);
  double frobenius = 0.0, largest = 0.0, gershgorin = 0.0, inverse_frobenius = 0.0, column = 0.0;
  for (Index i = 0; i < n; ++i) {
    if (d(i) == 0.0) return {INFINITY, 0.0};  // det B = prod d_i
    beta(2 * i) = d(i) * d(i);
    largest = std::max(largest, std::abs(d(i)));
    // a Golub-Kahan row holds two neighbouring off-diagonals: e_(i-1), d_i and d_i, e_i
    gershgorin = std::max(gershgorin, std::abs(d(i)) + (i ? std::abs(e(i - 1)) : 0.0));
    if (i + 1 < n) {
      beta(2 * i + 1) = e(i) * e(i);
      largest = std::max(largest, std::abs(e(i)));
      gershgorin = std::max(gershgorin, std::abs(d(i)) + std::abs(e(i)));
    }
    // |B^-1 e_i|^2 = (1 + e_(i-1)^2 |B^-1 e_(i-1)|^2) / d_i^2: B^-1's columns, no cancellation
    column = (1.0 + (i ? e(i - 1) * e(i - 1) * column : 0.0)) / (d(i) * d(i));
    inverse_frobenius += column;
  }
  frobenius = std::sqrt(beta.sum());
  // sigma_max in [largest entry, min(|B|_F, Gershgorin's bound)]: Laguerre from above (the
  // nearer the start, the fewer passes where the largest singular values cluster, as in a
  // chain of alike loops). sigma_min in [1/|B^-1|_F, min(|d_0|, |d_(n-1)|)] (a row and a
  // column of B): from below, or from above if rounding put the lower bound past it.
  const double hi_max = std::min(frobenius, gershgorin) * (1.0 + 4.0 * EPS);
  const double lo_min = (1.0 - 4.0 * EPS) / std::sqrt(inverse_frobenius);
  const double hi_min = std::min(std::abs(d(0)), std::abs(d(n - 1))) * (1.0 + 4.0 * EPS);
  const bool below = count_below(beta, lo_min) == n;
  EigenvalueSearch searches[2] = {{int(2 * n - 1), hi_max, false, largest * (1.0 - 4.0 * EPS), hi_max},
                                  {int(n), below ? lo_min : hi_min, below, below ? lo_min : 0.0, hi_min}};
  double found[2];
  find_eigenvalues(beta, searches, found);
  const double s_max = found[0], s_min = found[1];
  if (!(s_min > 0.0)) return {INFINITY, 0.0};
  return {s_max / s_min, std::ldexp(s_min, exponent)};
}

double det_of(const MatrixXd& A) {
  const Index n = A.rows();
  if (n == 1) return A(0, 0);
  if (n == 2) return A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return A.partialPivLu().determinant();
}

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
  std::vector<Index> child_cols, parent_cols;
};

struct Node {
  double p = 0.0;
  VectorXd q, d1, d2;
  std::vector<int> signs;
  double condition = 1.0, sigma_min = 1.0, velocity_residual = 0.0, acceleration_residual = 0.0, residual = 0.0;
};

class Core {
 public:
  Core(const std::vector<int>& types, const std::vector<int>& parents, const Eigen::Ref<const RowMatrix>& placements,
       const Eigen::Ref<const RowMatrix>& axes, const std::vector<int>& frame_parents,
       const Eigen::Ref<const RowMatrix>& frame_placements, const std::vector<int>& cut_types,
       const std::vector<int>& cut_parent, const std::vector<int>& cut_child,
       const Eigen::Ref<const RowMatrix>& cut_axes, const Eigen::Ref<const RowMatrix>& cut_child_axes,
       const std::vector<MatrixXd>& rows6, const std::vector<MatrixXd>& full, const std::vector<int>& drv_v,
       const std::vector<int>& dep_v, const std::vector<int>& drv_q, const std::vector<int>& drv_continuous,
       const VectorXd& v_scale, const std::vector<std::vector<int>>& block_rows,
       const std::vector<std::vector<int>>& block_cols, double tol)
      : drv_v_(drv_v), dep_v_(dep_v), drv_q_(drv_q), drv_continuous_(drv_continuous), tol_(tol) {
    const size_t nj = types.size();
    if (parents.size() != nj || size_t(placements.rows()) != nj || size_t(axes.rows()) != nj)
      throw std::invalid_argument("joint arrays of different lengths");
    for (size_t j = 0; j < nj; ++j) {
      model_.addJoint(pin::JointIndex(parents[j]), joint_model(types[j], axes.row(j).transpose()),
                      placement_of(placements.row(j).data()), "j" + std::to_string(j + 1));
    }
    for (size_t f = 0; f < frame_parents.size(); ++f) {
      const pin::JointIndex parent = pin::JointIndex(frame_parents[f]);
      frames_.push_back(model_.addFrame(pin::Frame("f" + std::to_string(f), parent,
                                                   placement_of(frame_placements.row(f).data()), pin::OP_FRAME)));
    }
    Index offset = 0;
    for (size_t c = 0; c < cut_types.size(); ++c) {
      if (rows6.at(c).cols() != 6 || full.at(c).cols() != 6 || rows6.at(c).rows() > 6 || full.at(c).rows() > 6)
        throw std::invalid_argument("closure rows must be at most 6 rows of 6 columns");
      Cut cut{cut_types[c], frames_.at(cut_parent[c]), frames_.at(cut_child[c]), cut_axes.row(c).transpose(),
              cut_child_axes.row(c).transpose(), rows6.at(c), full.at(c), offset, false};
      cut.ground = model_.frames[cut.parent].parentJoint == 0;
      relative_columns(cut);
      offset += cut.rows6.rows();
      cuts_.push_back(cut);
    }
    rows_ = offset;
    data_ = pin::Data(model_);
    const Index nv = model_.nv;
    if (v_scale.size() != nv) throw std::invalid_argument("velocity scale of the wrong size");
    v_scale_ = v_scale;
    v_scale_inv_ = v_scale.cwiseInverse();
    dep_scale_.resize(Index(dep_v_.size()));
    for (size_t i = 0; i < dep_v_.size(); ++i) dep_scale_(Index(i)) = v_scale(dep_v_[i]);
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
  }

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }
  std::vector<int> idx_q() const { return std::vector<int>(model_.idx_qs.begin() + 1, model_.idx_qs.end()); }
  std::vector<int> idx_v() const { return std::vector<int>(model_.idx_vs.begin() + 1, model_.idx_vs.end()); }

  // ---------------------------------------------------------------- pieces (also for tests)
  VectorXd residual(const VectorXd& q) {
    VectorXd r(rows_);
    residual_into(q, r);
    return r;
  }

  // The independent closure rows at q; leaves joint placements, Jacobians and the cut
  // frames' placements in data_ (LoopSolver._residual).
  void residual_into(const VectorXd& q, VectorXd& r) {
    pin::computeJointJacobians(model_, data_, q);
    for (const Cut& cut : cuts_) {
      pin::updateFramePlacement(model_, data_, cut.parent);
      pin::updateFramePlacement(model_, data_, cut.child);
      r.segment(cut.offset, cut.rows6.rows()).noalias() = cut.rows6 * error6(cut);
    }
  }

  double full_residual() const {
    double worst = 0.0;
    for (const Cut& cut : cuts_) worst = std::max(worst, max_abs(cut.full * error6(cut)));
    return worst;
  }

  MatrixXd jacobian(bool newton) {
    jacobian_into(newton);
    return J_;
  }

  // J_ = the stacked rows' Jacobian, Jdep_ its dependent columns (data_ at q).
  void jacobian_into(bool newton) {
    for (const Cut& cut : cuts_) relative_jacobian(cut, newton);
    for (size_t i = 0; i < dep_v_.size(); ++i) Jdep_.col(Index(i)) = J_.col(dep_v_[i]);
  }

  VectorXd drift(const VectorXd& q, const VectorXd& v) {
    VectorXd out(rows_);
    drift_into(q, v, out);
    return out;
  }

  void drift_into(const VectorXd& q, const VectorXd& v, VectorXd& out) {
    pin::forwardKinematics(model_, data_, q, v, zero_);
    for (const Cut& cut : cuts_) {
      const pin::SE3 &MP = data_.oMf[cut.parent], &MC = data_.oMf[cut.child];
      const pin::Motion vP = cut.ground ? pin::Motion::Zero()
                                        : pin::getFrameVelocity(model_, data_, cut.parent, pin::LOCAL_WORLD_ALIGNED);
      const pin::Motion vC = pin::getFrameVelocity(model_, data_, cut.child, pin::LOCAL_WORLD_ALIGNED);
      const pin::Motion aP = cut.ground ? pin::Motion::Zero()
                                        : pin::getFrameClassicalAcceleration(model_, data_, cut.parent,
                                                                             pin::LOCAL_WORLD_ALIGNED);
      const pin::Motion aC = pin::getFrameClassicalAcceleration(model_, data_, cut.child, pin::LOCAL_WORLD_ALIGNED);
      const Vector3d wP = vP.angular(), delta = MC.translation() - MP.translation();
      const Vector3d dv = vC.linear() - vP.linear();
      const Vector3d d = dv - wP.cross(delta);
      const Vector3d d_dot = aC.linear() - aP.linear() - aP.angular().cross(delta) - wP.cross(dv);
      Vector6d e;
      e.head<3>() = MP.rotation().transpose() * (d_dot - wP.cross(d));
      e.tail<3>() = MP.rotation().transpose() * (aC.angular() - aP.angular() - wP.cross(vC.angular() - wP));
      out.segment(cut.offset, cut.rows6.rows()).noalias() = cut.rows6 * e;
    }
  }

  // ---------------------------------------------------------------- the corrector
  // LoopSolver.correct(strict=True): full Newton steps, each at least halving the
  // residual; the polish step of `close`; the full-residual check. False: no root here.
  bool correct(VectorXd& q, const VectorXd& drivers, int max_iterations, double& residual_left) {
    set_drivers(q, drivers);
    VectorXd& r = r_;
    residual_into(q, r);
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
      polish(q, r, norm);
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
  void node_at(Node& node, const VectorXd& d) {
    // One factorization of the dimensionless J_dep (columns times dep_scale_) serves the
    // condition number and both solves; a dependent rate is dep_scale_ times its unknown.
    jacobian_into(false);
    scaled_ = Jdep_ * dep_scale_.asDiagonal();
    square_.factor(scaled_);
    // The condition number of J_dep with its rows and columns in block order (a
    // permutation: the same singular values), where a chain of loops is a band matrix.
    const MatrixXd* conditioned = &scaled_;
    if (!block_rows_.empty()) {
      permuted_ = scaled_(block_rows_, block_cols_);
      conditioned = &permuted_;
    }
    auto [condition, sigma_min] = condition_of(*conditioned, square_.singular(), condition_work_);
    node.condition = condition;
    node.sigma_min = sigma_min;
    signs_into(Jdep_, node.signs);
    VectorXd &v = node.d1, &a = node.d2;
    v.setZero(model_.nv);
    a.setZero(model_.nv);
    for (size_t i = 0; i < drv_v_.size(); ++i) v(drv_v_[i]) = d(Index(i));
    rhs_.noalias() = -(J_ * v);  // driver columns only: v is zero elsewhere yet
    square_.solve(rhs_, dstep_);
    for (size_t i = 0; i < dep_v_.size(); ++i) v(dep_v_[i]) = dep_scale_(Index(i)) * dstep_(Index(i));
    drift_into(node.q, v, drift_);
    rhs_ = -drift_;
    square_.solve(rhs_, dstep_);
    for (size_t i = 0; i < dep_v_.size(); ++i) a(dep_v_[i]) = dep_scale_(Index(i)) * dstep_(Index(i));
    rhs_.noalias() = J_ * v;
    node.velocity_residual = max_abs(rhs_);
    rhs_.noalias() = J_ * a;
    rhs_ += drift_;
    node.acceleration_residual = max_abs(rhs_);
  }

  // Path.step from `from` to p; 0 and `out` filled on success, else why it failed:
  // 1 corrector, 2 trust region, 3 singular, 4 turn, 5 signature changed (a change point
  // when `change` is set: the Python path takes it and names it).
  int step(const Node& from, double p, const VectorXd& x0, const VectorXd& d, double unit, Node& out, bool& change) {
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
    for (int s : out.signs)
      if (s == 0) return 3;
    if (!(out.condition <= SINGULAR_NODE)) return 3;
    const double turn = turn_between(from, out, unit);
    if (turn > MAX_TURN) return 4;
    if (out.signs != from.signs) {
      change = std::abs(h) * unit <= 1e-3 && turn < 0.1 * MAX_TURN;
      return 5;
    }
    return 0;
  }

  // The range mode of solve_cycle._Cycle: from the node (p0, q0, d1, d2) along drivers
  // x(p) = x0 + p d to each of `targets` in turn (Path.follow: first step at most
  // MAX_STEP, doubled after a success, halved after a failure down to PIVOT_BELOW).
  // Returns (poses done, why it stopped, q, d1, d2, accuracy columns).
  nb::tuple follow(double p0, const VectorXd& q0, const VectorXd& d1, const VectorXd& d2, const std::vector<int>& signs0,
                   double condition0, const VectorXd& x0, const VectorXd& d, double unit, const VectorXd& targets,
                   double max_condition) {
    if (Index(dep_v_.size()) != rows_) throw std::invalid_argument("the dependent Jacobian must be square");
    const Index n = targets.size();
    RowMatrix Q(n, model_.nq), D1(n, model_.nv), D2(n, model_.nv);
    RowMatrix acc(n, 7);  // residual, iterations, condition, sigma_min, velocity and acceleration residuals, steps
    Index done = 0;
    int stop = DONE;
    long attempts = 0;
    {
      nb::gil_scoped_release release;
      Node node, next;
      node.p = p0;
      node.q = q0;
      node.d1 = d1;
      node.d2 = d2;
      node.signs = signs0;
      node.condition = condition0;
      for (; done < n && stop == DONE; ++done) {
        const double target = targets(done);
        double h = std::copysign(std::min(std::abs(target - node.p), MAX_STEP / unit), target - node.p);
        long iterations = 0, steps = 0;
        while (node.p != target) {
          if (++attempts % SIGNAL_EVERY == 0) check_signals();  // a span of many turns takes long
          const double remaining = target - node.p;
          h = std::copysign(std::min(std::abs(h), std::abs(remaining)), remaining);
          bool change = false;
          const int why = step(node, std::abs(h) < std::abs(remaining) ? node.p + h : target, x0, d, unit, next, change);
          if (why == 0) {
            std::swap(node, next);
            iterations += iterations_;
            ++steps;
            h *= 2.0;
            continue;
          }
          if (why == 5 && change) {
            stop = SIGNATURE_CHANGED;
            break;
          }
          if (std::abs(h) * unit > PIVOT_BELOW) {
            h *= 0.5;
            continue;
          }
          stop = NEEDS_PIVOT;
          break;
        }
        if (stop != DONE) break;
        if (node.condition > max_condition) {
          stop = CONDITION;
          break;
        }
        if (!node.d1.allFinite() || !node.d2.allFinite()) {
          stop = NOT_FINITE;
          break;
        }
        Q.row(done) = node.q.transpose();
        D1.row(done) = node.d1.transpose();
        D2.row(done) = node.d2.transpose();
        acc.row(done) << node.residual, double(iterations), node.condition, node.sigma_min, node.velocity_residual,
            node.acceleration_residual, double(steps);
      }
    }
    return nb::make_tuple(done, stop, Q.topRows(done).eval(), D1.topRows(done).eval(), D2.topRows(done).eval(),
                          acc.topRows(done).eval());
  }

  // Path.node at a closed q: the path derivatives at driver velocity d, the signature,
  // the condition number and the residuals (closure, velocity, acceleration).
  nb::tuple node(const VectorXd& q, const VectorXd& d) {
    if (q.size() != model_.nq || d.size() != Index(drv_v_.size())) throw std::invalid_argument("q or d of the wrong size");
    Node out;
    out.q = q;
    residual_into(q, r_);
    out.residual = std::max(max_abs(r_), full_residual());
    node_at(out, d);
    return nb::make_tuple(out.d1, out.d2, out.signs, out.condition, out.sigma_min, out.velocity_residual,
                          out.acceleration_residual, out.residual);
  }

  // ---------------------------------------------------------------- rate problems
  // RateSolver.solve at every row of Q, for square tasks ("exact"): closure rows stacked
  // over task rows (frame Jacobian rows in world axes, or the frame's own with `local`),
  // made dimensionless by `row_scale` and the velocity scale; v and a by LU. A pose whose
  // stacked Jacobian is not square, or conditioned worse than max_condition, gets status
  // 1 and no numbers: the Python path names it.
  nb::tuple rates(const Eigen::Ref<const RowMatrix>& Q, const std::vector<int>& task_frames,
                  const std::vector<std::vector<int>>& task_rows, const std::vector<int>& task_local,
                  const VectorXd& x_dot, const VectorXd& x_ddot, const VectorXd& row_scale, double max_condition) {
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
  nb::tuple frame_motion(const Eigen::Ref<const RowMatrix>& Q, const Eigen::Ref<const RowMatrix>& V,
                         const Eigen::Ref<const RowMatrix>& A, const std::vector<int>& frames) {
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
  RowMatrix pinocchio_passes(const Eigen::Ref<const RowMatrix>& Q, const Eigen::Ref<const RowMatrix>& V,
                             int jacobians) {
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

  double tol() const { return tol_; }
  void set_tol(double tol) { tol_ = tol; }
  int iterations() const { return iterations_; }
  // Diagonal blocks the dependent solves go through (0: the whole matrix at once).
  int solve_blocks() const { return int(square_.blocks()); }
  double moved() const { return moved_; }

  std::vector<int> signs(const MatrixXd& J_dep) {
    std::vector<int> out;
    signs_into(J_dep, out);
    return out;
  }

  // The sign of each block's determinant (branches.AssemblyStructure.signs).
  void signs_into(const MatrixXd& J_dep, std::vector<int>& out) {
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

 private:
  Vector6d error6(const Cut& cut) const {
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

  // The columns of the cut's relative Jacobian that can be nonzero (Cut::child_cols).
  void relative_columns(Cut& cut) const {
    const auto& P = model_.supports[model_.frames[cut.parent].parentJoint];
    const auto& C = model_.supports[model_.frames[cut.child].parentJoint];
    auto add = [this](std::vector<Index>& cols, const std::vector<pin::JointIndex>& from,
                      const std::vector<pin::JointIndex>& other) {
      for (pin::JointIndex j : from) {
        if (j == 0 || std::find(other.begin(), other.end(), j) != other.end()) continue;
        for (int k = 0; k < model_.nvs[j]; ++k) cols.push_back(Index(model_.idx_vs[j] + k));
      }
    };
    add(cut.child_cols, C, P);
    add(cut.parent_cols, P, C);
  }

  // Rows offset .. offset + k of J_ = the cut's rows6 times its (6, nv) map from joint
  // velocities to (r_dot, w) of C in P; with `newton`, orientation rows carry the
  // derivative of the error measure instead (Closure.residual_jacobian). Columns come
  // from data_.J (world axes, at the origin: pin::getFrameJacobian's source), only those
  // of Cut::child_cols and parent_cols; J_'s other columns of these rows stay zero.
  void relative_jacobian(const Cut& cut, bool newton) {
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
    Vector6d e;
    for (Index c : cut.child_cols) {  // C's frame velocity at C, in P's axes
      const Vector3d w = data_.J.col(c).tail<3>();
      e.head<3>().noalias() = RT * (data_.J.col(c).head<3>() + w.cross(pC));
      e.tail<3>().noalias() = MRT * w;
      J_.block(cut.offset, c, k, 1).noalias() = cut.rows6 * e;
    }
    for (Index c : cut.parent_cols) {  // minus P's frame velocity at P, and P turning delta
      const Vector3d w = data_.J.col(c).tail<3>();
      const Vector3d v = data_.J.col(c).head<3>() + w.cross(pP);
      e.head<3>().noalias() = RT * (delta.cross(w) - v);
      e.tail<3>().noalias() = -(MRT * w);
      J_.block(cut.offset, c, k, 1).noalias() = cut.rows6 * e;
    }
  }

  // The assembly blocks (branches.AssemblyStructure: the irreducible diagonal blocks of
  // J_dep's block-triangular form) in an order for forward substitution, each with the
  // columns of earlier blocks its rows touch (its cut's support columns: J_dep is exactly
  // zero elsewhere). None (the whole matrix at once) where there is one block, where the
  // blocks do not partition a square J_dep into square blocks, or where no order has every
  // block touch only earlier ones.
  std::vector<DiagonalBlock> ordered_blocks() const {
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
          for (Index v : *cols) {
            const Index c = dep_col[size_t(v)];
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

  void set_drivers(VectorXd& q, const VectorXd& drivers) const {
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
  void move_into(const VectorXd& q, const VectorXd& step, VectorXd& out) {
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
  void polish(VectorXd& q, VectorXd& r, double& norm) {
    jacobian_into(true);
    rhs_ = -r;
    square_.factor(Jdep_);
    square_.solve(rhs_, dstep_);
    if (!dstep_.allFinite()) return;
    double alpha = 1.0;
    for (int k = 0; k <= LINE_SEARCH_HALVINGS; ++k, alpha *= 0.5) {
      move_into(q, alpha * dstep_, q_new_);
      residual_into(q_new_, r_new_);
      const double trial_norm = max_abs(r_new_);
      if (trial_norm < norm) {
        q.swap(q_new_);
        r.swap(r_new_);
        norm = trial_norm;
        return;
      }
    }
    residual_into(q, r);  // data back at q
  }

  double turn_between(const Node& a, const Node& b, double unit) const {
    const VectorXd ta = a.d1.cwiseProduct(v_scale_inv_), tb = b.d1.cwiseProduct(v_scale_inv_);
    const double na = std::sqrt(ta.squaredNorm() + unit * unit), nb_ = std::sqrt(tb.squaredNorm() + unit * unit);
    const double c = (ta.dot(tb) + unit * unit) / (na * nb_);
    return std::acos(std::max(-1.0, std::min(1.0, c)));
  }

  pin::Model model_;
  pin::Data data_;
  std::vector<pin::FrameIndex> frames_;
  std::vector<Cut> cuts_;
  Index rows_ = 0;
  std::vector<int> drv_v_, dep_v_, drv_q_, drv_continuous_;
  VectorXd dep_scale_, v_scale_, v_scale_inv_, step_, zero_;
  std::vector<std::vector<int>> blocks_rows_, blocks_cols_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> tmp3_;
  // work buffers, sized once: a pose allocates nothing
  MatrixXd J_, Jdep_, scaled_, permuted_;
  std::vector<Index> block_rows_, block_cols_;  // J_dep's rows and columns in block order
  std::vector<MatrixXd> block_buffers_;
  VectorXd r_, r_new_, rhs_, dstep_, drift_, q_new_, predicted_, x_;
  SquareSolve square_;
  ConditionWork condition_work_;
  double tol_;
  int iterations_ = 0;
  double moved_ = 0.0;
};

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "pinmech's compiled core: sweeps of closed-loop mechanisms on Pinocchio (see pinmech/core.py)";
  m.attr("DEFAULT_TOL") = DEFAULT_TOL;
  m.attr("POLISH") = POLISH;
  m.attr("MAX_NEWTON_STEP") = MAX_NEWTON_STEP;
  m.attr("MAX_STEP") = MAX_STEP;
  m.attr("TRUST") = TRUST;
  m.attr("MAX_TURN") = MAX_TURN;
  m.attr("PIVOT_BELOW") = PIVOT_BELOW;
  m.attr("CORRECTOR_ITERATIONS") = CORRECTOR_ITERATIONS;
  m.attr("SINGULAR_NODE") = SINGULAR_NODE;
  m.attr("PINOCCHIO_VERSION") = PINOCCHIO_VERSION;
  m.def(
      "condition",
      [](const MatrixXd& A) {
        if (A.rows() != A.cols()) throw std::invalid_argument("condition: A must be square");
        ConditionWork work;
        const Eigen::PartialPivLU<MatrixXd> lu(A);
        return condition_of(A, A.rows() > 0 && lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0, work);
      },
      "2-norm condition number and smallest singular value of a square A, as the core computes them");
  nb::class_<Core>(m, "Core")
      .def(nb::init<const std::vector<int>&, const std::vector<int>&, const Eigen::Ref<const RowMatrix>&,
                    const Eigen::Ref<const RowMatrix>&, const std::vector<int>&, const Eigen::Ref<const RowMatrix>&,
                    const std::vector<int>&, const std::vector<int>&, const std::vector<int>&,
                    const Eigen::Ref<const RowMatrix>&, const Eigen::Ref<const RowMatrix>&,
                    const std::vector<MatrixXd>&, const std::vector<MatrixXd>&, const std::vector<int>&,
                    const std::vector<int>&, const std::vector<int>&, const std::vector<int>&, const VectorXd&,
                    const std::vector<std::vector<int>>&, const std::vector<std::vector<int>>&, double>())
      .def_prop_ro("nq", &Core::nq)
      .def_prop_ro("nv", &Core::nv)
      .def_prop_ro("idx_q", &Core::idx_q)
      .def_prop_ro("idx_v", &Core::idx_v)
      .def_prop_rw("tol", &Core::tol, &Core::set_tol)
      .def_prop_ro("iterations", &Core::iterations)
      .def_prop_ro("solve_blocks", &Core::solve_blocks)
      .def_prop_ro("moved", &Core::moved)
      .def("residual", &Core::residual)
      .def("full_residual", &Core::full_residual)
      .def("jacobian", &Core::jacobian, nb::arg("newton") = false)
      .def("drift", &Core::drift)
      .def("signs", &Core::signs)
      .def("correct",
           [](Core& core, VectorXd q, const VectorXd& drivers, int max_iterations) {
             double residual = NAN;
             const bool ok = core.correct(q, drivers, max_iterations, residual);
             return nb::make_tuple(q, ok ? nb::cast(residual) : nb::none());
           })
      .def("follow", &Core::follow)
      .def("node", &Core::node)
      .def("rates", &Core::rates)
      .def("frame_motion", &Core::frame_motion)
      .def("pinocchio_passes", &Core::pinocchio_passes);
}
