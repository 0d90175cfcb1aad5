// Condition numbers of square matrices (condition.cpp): pure Eigen, no Pinocchio.
#pragma once

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace pinmech {

// Work buffers of condition_of (sized on first use), and the extreme singular values it
// found last (in A's units; 0: none yet), where the next search starts when they still
// bracket (certified by Sturm counts: a start changes the passes, not the result's bound).
struct ConditionWork {
  Eigen::MatrixXd B;
  Eigen::VectorXd d, e, tmp, beta;  // B's diagonal and superdiagonal; squared Golub-Kahan off-diagonals
  double last_max = 0.0, last_min = 0.0;
};

// A's structural band: with A's rows and columns in the order `rows`, `cols` (empty: as
// they are), every entry more than `lower` below or `upper` above the diagonal is exactly
// zero (the caller knows it from the matrix's structure).
struct Band {
  Eigen::Index lower, upper;
  std::vector<Eigen::Index> rows, cols;
};

// 2-norm condition number and smallest singular value of a square A (condition.cpp).
// `singular`: the caller's factorization of A met an exact zero pivot (used above 3x3).
// `band`: A's structural band, or null to find the band of exact zeros by a scan.
std::pair<double, double> condition_of(const Eigen::MatrixXd& A, bool singular, ConditionWork& work,
                                       const Band* band = nullptr);

}  // namespace pinmech
