#pragma once
/// \file
/// The dense inverse and product the element tables are built with (shape functions, Bézier
/// bases). Header-only, they are inline; with meshmotion::compiled (MESHMOTION_COMPILED) they
/// are compiled once, in src/tables.cpp, so that a program including the headers does not
/// compile Eigen's dense LU for tables it reads from the library (docs/compiled.md).

#include "meshmotion/core/types.hpp"

#include <Eigen/LU>

namespace meshmotion::detail {

#if !defined(MESHMOTION_COMPILED)
[[nodiscard]] inline Eigen::MatrixXd table_inverse(const Eigen::MatrixXd& m) { return m.inverse(); }
[[nodiscard]] inline Eigen::MatrixXd table_product(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return a * b; }
#elif defined(MESHMOTION_DEFINE_TABLE_KERNELS)
[[nodiscard]] Eigen::MatrixXd table_inverse(const Eigen::MatrixXd& m) { return m.inverse(); }
[[nodiscard]] Eigen::MatrixXd table_product(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return a * b; }
#else
[[nodiscard]] Eigen::MatrixXd table_inverse(const Eigen::MatrixXd& m);
[[nodiscard]] Eigen::MatrixXd table_product(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
#endif

}  // namespace meshmotion::detail
