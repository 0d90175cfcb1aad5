// pinmech's compiled core: condition numbers (see core.hpp for the whole).
// ---------------------------------------------------------------- condition numbers
// From 3x3 up the singular values come from a bidiagonalization B = U^T A V: plane
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

#include "condition.hpp"

#include <Eigen/Householder>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pinmech {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

constexpr double EPS = std::numeric_limits<double>::epsilon();
constexpr double PIVMIN = std::numeric_limits<double>::min();
constexpr int LAGUERRE_PASSES = 20;


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
  // no underflow in the squares (no overflow either: B's entries stay below n, its
  // largest at most 1 before its orthogonal transformations)
  if (!(r > 1e-150)) r = std::hypot(a, b);
  const double inv = 1.0 / r;
  return {a * inv, b * inv};
}

void rotate_rows(MatrixXd& R, Index p, Index q, Index from, Index to, Rotation g) {
  const Index stride = R.outerStride();
  double *rp = &R(p, from), *rq = &R(q, from);
  for (Index t = from; t <= to; ++t, rp += stride, rq += stride) {
    const double x = *rp, y = *rq;
    *rp = g.c * x + g.s * y;
    *rq = g.c * y - g.s * x;
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

// The bulge chases of band_bidiagonalize, several at once. For each k (in order) and each
// j from k + width down to k + 2 (a "chase"): a column rotation clears R(k, j), and the
// bulge it leaves below the diagonal is chased down the band, `width` rows a step, by a
// row and a column rotation (as LAPACK's dgbbrd). Each chase is a chain of dependent
// rotations (a square root and a division each), so one at a time the CPU waits on them;
// here a chase starts, and steps on, as soon as what it touches lies wholly above and to
// the left of everything the chases before it still have to touch (their steps only move
// down the band). Operations on disjoint entries commute, so this performs exactly the
// sequential order's arithmetic, bit for bit, with up to n / (2 width) chases in flight
// whose rotations the CPU overlaps. A chase touches rows and columns [k, j] at its start
// and [r - 1, min(n - 1, r + width)] at a step from the bulge at (r, r - 1).
struct Chase {
  Index k, r;  // its row; its bulge's row (r, r - 1)
};

void chase_bulges(MatrixXd& R, Index width) {
  const Index n = R.rows();
  constexpr int MAX_CHASES = 64;
  Chase active[MAX_CHASES];
  int count = 0;
  Index next_k = 0, next_j = std::min(n - 1, width);  // the next chase to start: (k, j)
  while (count > 0 || next_k + 2 < n) {
    Index bound = n;  // no index at or past it may be touched: the earlier chases' least one to come
    int kept = 0;
    for (int i = 0; i < count; ++i) {
      Chase c = active[i];
      if (std::min(n - 1, c.r + width) < bound) {  // a step: the bulge at (r, r - 1), then (r - 1, r + width)
        const Index r = c.r;
        if (R(r, r - 1) != 0.0) {
          rotate_rows(R, r - 1, r, r - 1, std::min(n - 1, r + width), rotation(R(r - 1, r - 1), R(r, r - 1)));
          R(r, r - 1) = 0.0;
        }
        const Index col = r + width;
        if (col > n - 1 || R(r - 1, col) == 0.0) continue;  // the chase has left the band
        rotate_columns(R, col - 1, col, r - 1, col, rotation(R(r - 1, col - 1), R(r - 1, col)));
        R(r - 1, col) = 0.0;
        c.r = col;
      }
      bound = std::min(bound, c.r - 1);
      active[kept++] = c;
    }
    count = kept;
    while (next_k + 2 < n && count < MAX_CHASES && next_j < bound) {  // start the next chases
      const Index k = next_k, j = next_j;
      if (--next_j < next_k + 2) {
        ++next_k;
        next_j = std::min(n - 1, next_k + width);
      }
      if (R(k, j) == 0.0) continue;
      rotate_columns(R, j - 1, j, k, j, rotation(R(k, j - 1), R(k, j)));
      R(k, j) = 0.0;
      active[count++] = {k, j};
      bound = j - 1;
    }
  }
}

// Upper bidiagonalization of a band matrix (nonzeros at most kl below and ku above the
// diagonal) in place by plane rotations, which keep the band: a QR clears the lower band
// (R then has upper bandwidth w = kl + ku), then each row's entries beyond the
// superdiagonal are cleared from the outside in by a column rotation, and the bulge this
// leaves below the diagonal is chased down the band, w rows a step, by alternating row and
// column rotations (as LAPACK's dgbbrd). About n^2 w rotations against the dense
// reflections' 8 n^3 / 3 flops; condition_of takes them where the band is narrow enough
// for that to pay (scripts/condition_time.py times both). It reads and writes only
// entries at most max(kl, 1) below and kl + ku + 1 above the diagonal (bulges included).
void band_bidiagonalize(ConditionWork& w, Index kl, Index ku) {
  MatrixXd& R = w.B;
  const Index n = R.rows();
  Index width = kl + ku;
  // column j's sweep mixes rows j .. j + kl, none of which reaches past j + kl + ku
  for (Index j = 0; j + 1 < n; ++j)
    for (Index i = std::min(n - 1, j + kl); i > j; --i) {
      if (R(i, j) == 0.0) continue;
      rotate_rows(R, i - 1, i, j, std::min(n - 1, j + width), rotation(R(i - 1, j), R(i, j)));
      R(i, j) = 0.0;
    }
  // R's upper bandwidth may be narrower than kl + ku where A's band is sparse (a chain of
  // loops: 2, not 3): chased in steps of the narrower one, the bulges take fewer rotations.
  Index reach = 0;
  for (Index i = 0; i + 1 < n; ++i)
    for (Index j = std::min(n - 1, i + width); j > i + reach; --j)
      if (R(i, j) != 0.0) {
        reach = j - i;
        break;
      }
  width = reach;
  if (width >= 2) chase_bulges(R, width);
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

}  // namespace

// 2-norm condition number and smallest singular value, as solve_loops._condition: closed
// forms up to 2x2, bidiagonalization from 3x3 up (Eigen's closed-form 3x3 eigenvalues of
// A^T A lost 1e-9 of the condition number at a repeated singular value, where rounding
// allows 1e-14: tests/test_core.py found it).
// `singular`: the caller's factorization of A (which it also solves with) met an exact zero
// pivot (used above 3x3).
namespace {

// 2-norm condition number and smallest singular value of a square A of 3 to
// JACOBI_MAX_N rows, by one-sided Jacobi (Hestenes): plane rotations of A's columns until
// every pair is orthogonal to |a_p . a_q| <= eps sqrt(|a_p|^2 |a_q|^2); the singular
// values are then the columns' norms. It is an SVD (backward stable, each sigma within
// about eps sigma_max, and relatively accurate for a well-scaled A: Demmel and Veselic,
// SIAM J. Matrix Anal. Appl. 13, 1992); at 3x3, with the size's loops unrolled, 1,400
// instructions against condition_of's 5,700 (bidiagonalization and bisection; callgrind on
// the 17.110 arm's 360 poses). Returns false (and condition_of goes on with the bidiagonalization) if the
// sweeps did not converge or A is not finite.
constexpr Index JACOBI_MAX_N = 6;
template <int N>
bool jacobi_condition_fixed(const MatrixXd& A, double& condition, double& sigma_min) {
  const double largest_entry = A.cwiseAbs().maxCoeff();
  if (!std::isfinite(largest_entry)) return false;
  if (largest_entry == 0.0) {
    condition = INFINITY;
    sigma_min = 0.0;
    return true;
  }
  int exponent = 0;  // B = A / 2^exponent, its largest entry in [1/2, 1): exact, no over- or underflow
  std::frexp(largest_entry, &exponent);
  const double scale = std::ldexp(1.0, -exponent);
  Eigen::Matrix<double, N, N> B = A * scale;
  constexpr double eps = std::numeric_limits<double>::epsilon();
  bool converged = false;
  for (int sweep = 0; sweep < 60 && !converged; ++sweep) {
    converged = true;
    for (int p = 0; p + 1 < N; ++p)
      for (int q = p + 1; q < N; ++q) {
        const double alpha = B.col(p).squaredNorm(), beta = B.col(q).squaredNorm(), gamma = B.col(p).dot(B.col(q));
        if (!(std::abs(gamma) > eps * std::sqrt(alpha * beta))) continue;
        converged = false;
        // the rotation that diagonalizes [alpha gamma; gamma beta] (Golub and Van Loan, 8.5.2);
        // past |zeta| = 1e150, sqrt(1 + zeta^2) is |zeta| to rounding (and would overflow)
        const double zeta = (beta - alpha) / (2.0 * gamma), size = std::abs(zeta);
        const double t = std::copysign(1.0, zeta) / (size + (size < 1e150 ? std::sqrt(1.0 + zeta * zeta) : size));
        const double c = 1.0 / std::sqrt(1.0 + t * t), s = c * t;
        const Eigen::Matrix<double, N, 1> bp = B.col(p);
        B.col(p) = c * bp - s * B.col(q);
        B.col(q) = s * bp + c * B.col(q);
      }
  }
  if (!converged) return false;
  const Eigen::Matrix<double, N, 1> sigma = B.colwise().norm().transpose();
  const double largest = sigma.maxCoeff(), smallest = sigma.minCoeff();
  sigma_min = smallest / scale;
  condition = smallest > 0 ? largest / smallest : INFINITY;
  return true;
}

// The size's own unrolled loops; false (the bidiagonalization instead) outside 3 to JACOBI_MAX_N.
bool jacobi_condition(const MatrixXd& A, double& condition, double& sigma_min) {
  switch (A.rows()) {
    case 3: return jacobi_condition_fixed<3>(A, condition, sigma_min);
    case 4: return jacobi_condition_fixed<4>(A, condition, sigma_min);
    case 5: return jacobi_condition_fixed<5>(A, condition, sigma_min);
    case 6: return jacobi_condition_fixed<6>(A, condition, sigma_min);
    default: return false;
  }
}

}  // namespace

std::pair<double, double> condition_of(const MatrixXd& A, bool singular, ConditionWork& work, const Band* band) {
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
  // 3x3 to 6x6 (an arm's task, a small loop's J_dep): one-sided Jacobi, a quarter of the
  // bidiagonalization's cost at 3x3; the bidiagonalization below if it does not converge.
  if (n <= JACOBI_MAX_N) {
    double condition = INFINITY, sigma_min = 0.0;
    if (jacobi_condition(A, condition, sigma_min)) return {condition, sigma_min};
  }
  // The band: the caller's structural one (J_dep's in block order: a chain of loops has
  // kl = 2, ku = 1), else that of the exact zeros; the rotations where they are cheaper
  // than the reflections (measured crossover). B = A / 2^exponent, its largest entry in
  // [1/2, 1): exact, and no over- or underflow; for the rotations in the band's order,
  // from the band's entries only (the rest are exact zeros).
  Index kl = n - 1, ku = n - 1;
  if (band != nullptr) {
    kl = std::min(band->lower, n - 1);
    ku = std::min(band->upper, n - 1);
  }
  int exponent = 0;
  if (band != nullptr && 11 * (kl + ku) <= 2 * n + 16) {
    const bool ordered = Index(band->rows.size()) == n && Index(band->cols.size()) == n;
    const auto row = [&](Index i) { return ordered ? band->rows[size_t(i)] : i; };
    const auto col = [&](Index j) { return ordered ? band->cols[size_t(j)] : j; };
    double largest_entry = 0.0;
    bool finite = true;
    for (Index j = 0; j < n; ++j)
      for (Index i = std::max(Index(0), j - ku); i <= std::min(n - 1, j + kl); ++i) {
        const double v = std::abs(A(row(i), col(j)));
        finite = finite && v <= std::numeric_limits<double>::max();
        largest_entry = std::max(largest_entry, v);
      }
    if (!finite) return {INFINITY, 0.0};
    std::frexp(largest_entry, &exponent);
    const double scale = std::ldexp(1.0, -exponent);
    work.B.resize(n, n);  // only the entries band_bidiagonalize touches: the band, zeros around it
    for (Index j = 0; j < n; ++j)
      for (Index i = std::max(Index(0), j - kl - ku - 1); i <= std::min(n - 1, j + std::max(kl, Index(1))); ++i)
        work.B(i, j) = i >= j - ku && i <= j + kl ? A(row(i), col(j)) * scale : 0.0;
    band_bidiagonalize(work, kl, ku);
  } else {
    const double largest_entry = A.cwiseAbs().maxCoeff();
    if (!std::isfinite(largest_entry)) return {INFINITY, 0.0};
    std::frexp(largest_entry, &exponent);
    work.B = A * std::ldexp(1.0, -exponent);
    if (band == nullptr) {
      kl = ku = 0;
      for (Index j = 0; j < n; ++j)
        for (Index i = 0; i < n; ++i)
          if (work.B(i, j) != 0.0) {
            kl = std::max(kl, i - j);
            ku = std::max(ku, j - i);
          }
    }
    if (11 * (kl + ku) <= 2 * n + 16) band_bidiagonalize(work, kl, ku);
    else bidiagonalize(work);
  }
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
  EigenvalueSearch searches[2] = {{int(2 * n - 1), hi_max, false, largest * (1.0 - 4.0 * EPS), hi_max},
                                  {int(n), hi_min, false, 0.0, hi_min}};
  // Warm start: the last call's values (a neighbouring pose's), where a Sturm count puts
  // each between its singular value and the next one (Laguerre then goes to the former,
  // monotonically); the count also narrows the bracket. Else the cold start: sigma_max
  // from above; sigma_min from below, or from above if rounding put the lower bound past it.
  const double scale = std::ldexp(1.0, -exponent);
  const double guesses[3] = {work.last_max * scale, work.last_min * scale, lo_min};
  int counts[3];
  const bool warm = guesses[0] > searches[0].lo && guesses[0] < hi_max && guesses[1] > 0.0 && guesses[1] < hi_min;
  if (warm) counts_below<3>(beta, guesses, counts);
  else counts[2] = count_below(beta, lo_min);
  bool min_started = false;
  for (int i = 0; warm && i < 2; ++i) {
    EigenvalueSearch& s = searches[i];
    if (counts[i] == s.index) {  // the guess is below the singular value, above the next one down
      s.x = s.lo = guesses[i];
      s.right = true;
    } else if (counts[i] == s.index + 1) {  // above it, below the next one up
      s.x = s.hi = guesses[i];
      s.right = false;
    } else {
      continue;
    }
    min_started = min_started || i == 1;
  }
  if (counts[2] == n) {  // lo_min is below sigma_min: the bracket's lower end, a start from below
    EigenvalueSearch& s = searches[1];
    s.lo = std::max(s.lo, lo_min);
    if (!min_started || (s.right && s.x < lo_min)) {
      s.x = lo_min;
      s.right = true;
    }
  }
  double found[2];
  find_eigenvalues(beta, searches, found);
  const double s_max = found[0], s_min = found[1];
  work.last_max = std::ldexp(s_max, exponent);
  work.last_min = std::ldexp(s_min, exponent);
  if (!(s_min > 0.0)) return {INFINITY, 0.0};
  return {s_max / s_min, std::ldexp(s_min, exponent)};
}

}  // namespace pinmech
