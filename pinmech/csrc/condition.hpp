// Condition numbers of square matrices (condition.cpp): pure Eigen, no Pinocchio.
#pragma once

#include <Eigen/Core>

#include <utility>

namespace pinmech {

// Work buffers of condition_of (sized on first use).
struct ConditionWork {
  Eigen::MatrixXd B;
  Eigen::VectorXd d, e, tmp, beta;  // B's diagonal and superdiagonal; squared Golub-Kahan off-diagonals
};

// 2-norm condition number and smallest singular value of a square A (condition.cpp).
// `singular`: the caller's factorization of A met an exact zero pivot (used above 3x3).
std::pair<double, double> condition_of(const Eigen::MatrixXd& A, bool singular, ConditionWork& work);

}  // namespace pinmech
