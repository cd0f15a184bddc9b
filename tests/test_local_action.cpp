// METHOD.md §2: the node residual E_c, computed by differentiating the reduced local action, is
// the gradient of the action sum under the unreduced variation p_c -> p_c + δp, g_c -> g_c exp(η)
// (then re-reduced through the connection). Checked against central finite differences of the
// whole action sum for the k = 2 beanie (SE(2), non-trivial connection, multipliers), at
// interior nodes and at the boundary nodes, where only the existing windows enter (the natural
// boundary conditions of a boundary value problem).
#include "helpers.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using problems::BeanieControl;

namespace {
constexpr int kN = 7;  // nodes 0..7, windows 0..5

struct Unreduced {
  std::array<double, kN + 1> psi;
  std::array<SE2::Element<double>, kN + 1> g;
  std::array<Eigen::Vector3d, kN - 1> lam;
};

std::vector<SE2::Element<double>> increments(const BeanieControl& b, const Unreduced& q) {
  std::vector<SE2::Element<double>> gt;
  for (int n = 0; n < kN; ++n)
    gt.push_back(SE2::compose(SE2::compose(SE2::inverse(q.g[n]), q.g[n + 1]),
                              b.connection<double>(Vec<double, 1>(q.psi[n]), Vec<double, 1>(q.psi[n + 1]))));
  return gt;
}

double action(const BeanieControl& b, const Unreduced& q, double h) {
  const auto gt = increments(b, q);
  double S = 0;
  for (int j = 0; j + 2 <= kN; ++j) {
    Window<BeanieControl, double> a;
    for (int i = 0; i < 3; ++i) a.p[i] = Vec<double, 1>(q.psi[j + i]);
    a.g = {gt[j], gt[j + 1]};
    S += augmented_lagrangian(b, a, Vec<double, 3>(q.lam[j]), h);
  }
  return S;
}
}  // namespace

TEST(LocalAction, NodeResidualIsTheGradientOfTheActionSumAtEveryNode) {
  BeanieControl b;
  b.par = {1.3, 0.9, 0.6, 0.8};
  const double h = 0.1;
  std::mt19937 rng(21);
  std::normal_distribution<double> n01;
  for (auto variant : {problems::BeanieConstraints::ExactRotation, problems::BeanieConstraints::Paper}) {
    b.variant = variant;
    Unreduced q;
    for (int n = 0; n <= kN; ++n) {
      q.psi[n] = 0.3 * n01(rng);
      q.g[n] = {0.5 * n01(rng), Eigen::Vector2d(n01(rng), n01(rng))};
    }
    for (auto& l : q.lam) l = Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const auto gt = increments(b, q);

    for (int c = 0; c <= kN; ++c) {
      const int first = std::max(0, c - 2), last = std::min(c, kN - 2);  // windows containing c
      const int o = first;                                              // block starts at node o
      NodeBlock<BeanieControl, double> blk;
      for (int i = 0; i <= 4; ++i) blk.p[i] = Vec<double, 1>(q.psi[std::min(o + i, kN)]);
      for (int i = 0; i < 4; ++i) blk.g[i] = gt[std::min(o + i, kN - 1)];
      for (int j = 0; j <= 2; ++j) blk.lam[j] = q.lam[std::min(o + j, kN - 2)];
      const Eigen::Vector4d E = node_residual(b, blk, c - o, first - o, last - o, h);

      // Central differences of the unreduced action: δψ_c, then g_c -> g_c exp(ε e_i).
      const double eps = 1e-6;
      Eigen::Vector4d fd;
      for (int i = 0; i < 4; ++i) {
        Unreduced plus = q, minus = q;
        if (i == 0) {
          plus.psi[c] += eps;
          minus.psi[c] -= eps;
        } else {
          Eigen::Vector3d xi = Eigen::Vector3d::Zero();
          xi(i - 1) = eps;
          plus.g[c] = SE2::compose(q.g[c], SE2::exp<double>(xi));
          minus.g[c] = SE2::compose(q.g[c], SE2::exp<double>(Eigen::Vector3d(-xi)));
        }
        fd(i) = (action(b, plus, h) - action(b, minus, h)) / (2 * eps);
      }
      // Central differences: error ~ eps^2 |S'''| + u |S| / eps ~ 1e-9 relative here.
      EXPECT_LT((E - fd).lpNorm<Eigen::Infinity>(), 1e-6 * std::max(1.0, fd.lpNorm<Eigen::Infinity>()))
          << "node " << c << "\nengine " << E.transpose() << "\nfd     " << fd.transpose();
    }
  }
}
