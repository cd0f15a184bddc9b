// SparseQR's rank test for a banded square matrix, in time linear in its size. Eigen's SparseQR
// (natural order, setPivotThreshold) clears work arrays of the full size at every column, O(n²)
// in all: 45 s of the beanie's solve on Galerkin 4 at N = 10⁶ (2.2e5 unknowns). The rank
// diagnosis (diagnostics.cpp) runs this first and the SparseQR only for a deficiency it finds.
#pragma once

#include <Eigen/SparseCore>

namespace lpshoot {

// Whether Householder QR of J in natural column order finds every column's remaining norm (its
// entries from the diagonal down, after the reflections of the columns before) at or above
// `threshold`, as SparseQR's test does; J square with bandwidths (kl, ku) (BandLU::bandwidths).
// O(n kl (kl + ku)) time, O(kl (kl + ku)) memory. False for a non-square J or an entry outside
// the bandwidths.
bool banded_qr_full_rank(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& J, int kl, int ku, double threshold);

}  // namespace lpshoot
