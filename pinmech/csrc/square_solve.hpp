// Square solves of the core (header only, pure Eigen): a small dense A x = b, and the
// dependent Jacobian's solve block by block.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>
#include <utility>
#include <vector>

namespace pinmech {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// The largest |entry| of a vector or of a vector expression (evaluated lazily: no temporary).
template <typename Derived>
inline double max_abs(const Eigen::MatrixBase<Derived>& x) {
  return x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
}

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

}  // namespace pinmech
