// The flops of one element, term by term from the kernels' formulas (a multiply or an add is
// one flop). Counted by hand once, here, from the code they name; the roofline lesson reads
// them so that no table types a number.
#include "apps/roofline/work.hpp"

namespace fem::roofline {

namespace {

// A 3x3 matrix times a 3x3 matrix: 27 multiplies, 18 adds. Times a 3-vector: 9 and 6.
constexpr double kMatMat3 = 45.0;
constexpr double kMatVec3 = 15.0;
// One Newton step of the polar decomposition, R <- (R + R^-T) / 2: the cofactors (27), the
// determinant from them (5), its inverse and the scaling (10), the average (18). The rotation
// needs at least this (chapter 08's warm start often stops after it); an SVD does more.
constexpr double kPolarStep = 60.0;

}  // namespace

double fused_element_flops() {
  // chapters/08_element_kernels/element_kernels.cpp, FusedElements::terms and scatter.
  const double edges = 18.0;                    // Ds and Dv: 18 differences of corners
  const double deformation = kMatMat3;          // F = Ds Dm^-1
  const double prediction = 2.0 * 28.0;         // R_k R_(k-1)^T R_k: two quaternion products
  const double rotation = kPolarStep;           // Newton from the prediction
  const double gradients = kMatMat3 + 6.0;      // r_a = R g_a (a = 1..3), r_0 = -(r_1 + r_2 + r_3)
  const double strain = 18.0 + kMatMat3;        // G = (Ds + s Dv) r^T
  const double stress = 9.0 + 9.0 + 3.0 + 6.0;  // P = V mu (G + G^T), trace, diagonal terms
  const double rhs = 4.0 * kMatVec3 + 12.0;     // -h P r_a for the 4 corners
  // stiffness_blocks, 10 distinct blocks: the outer product r_b r_a^T (9), its two scaled
  // terms and their sum (27), the dot product (5), the diagonal term (4).
  const double blocks = 10.0 * (9.0 + 27.0 + 5.0 + 4.0);
  const double scatter = 12.0 + 16.0 * 9.0;  // b += 4 corner terms, A += 16 blocks
  return edges + deformation + prediction + rotation + gradients + strain + stress + rhs + blocks +
         scatter;
}

double reference_force_flops() {
  // common/model.cpp compute_rotations_and_forces: f_e = -R K0 (R^T x_e - X_e), then f += f_e.
  const double deformation = 9.0 + kMatMat3;   // Ds, F = Ds Dm^-1
  const double local = 4.0 * kMatVec3 + 12.0;  // R^T x_a for 4 corners, minus X_e
  const double stiffness = 144.0 + 132.0;      // K0 (12 x 12) times a 12-vector
  const double rotate = 4.0 * kMatVec3;        // R times the 4 corner forces
  return deformation + kPolarStep + local + stiffness + rotate + 12.0;
}

double reference_block_flops() {
  // common/element.cpp: the 16 blocks R K0_ab R^T, each two 3x3 products, added into df/dx.
  return 16.0 * (2.0 * kMatMat3 + 9.0);
}

}  // namespace fem::roofline
