#include "sim/cloth_forces.h"

#include <cmath>

#include <Eigen/LU>
#include <Eigen/Geometry>

namespace clothwind::sim {
namespace {

// Rows: d F / d x_i coefficients: F.col(j) = sum_i x_i * B(i, j).
Eigen::Matrix<double, 3, 2> ShapeCoefficients(const TriangleRest& rest) {
  Eigen::Matrix<double, 3, 2> B;
  B.row(1) = rest.Dm_inv.row(0);
  B.row(2) = rest.Dm_inv.row(1);
  B.row(0) = -(B.row(1) + B.row(2));
  return B;
}

}  // namespace

TriangleRest MakeTriangleRest(const Eigen::Vector2d& u0, const Eigen::Vector2d& u1,
                              const Eigen::Vector2d& u2) {
  Eigen::Matrix2d Dm;
  Dm.col(0) = u1 - u0;
  Dm.col(1) = u2 - u0;
  TriangleRest r;
  r.Dm_inv = Dm.inverse();
  r.area = 0.5 * std::abs(Dm.determinant());
  return r;
}

Eigen::Matrix<double, 3, 2> DeformationGradient(const Vector9d& x, const TriangleRest& rest) {
  Eigen::Matrix<double, 3, 2> Ds;
  Ds.col(0) = x.segment<3>(3) - x.segment<3>(0);
  Ds.col(1) = x.segment<3>(6) - x.segment<3>(0);
  return Ds * rest.Dm_inv;
}

Eigen::Matrix2d GreenStrain(const Vector9d& x, const TriangleRest& rest) {
  const Eigen::Matrix<double, 3, 2> F = DeformationGradient(x, rest);
  return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
}

StretchingTerms StretchingForce(const Vector9d& x, const TriangleRest& rest,
                                const Eigen::Vector4d& k, bool definite) {
  const Eigen::Matrix<double, 3, 2> B = ShapeCoefficients(rest);
  const Eigen::Matrix<double, 3, 2> F = DeformationGradient(x, rest);
  const Eigen::Vector3d Fu = F.col(0), Fv = F.col(1);
  const double G00 = 0.5 * (Fu.dot(Fu) - 1), G11 = 0.5 * (Fv.dot(Fv) - 1), G01 = 0.5 * Fu.dot(Fv);
  Vector9d g00, g11, g01;  // gradients of the strain components
  for (int i = 0; i < 3; ++i) {
    g00.segment<3>(3 * i) = B(i, 0) * Fu;
    g11.segment<3>(3 * i) = B(i, 1) * Fv;
    g01.segment<3>(3 * i) = 0.5 * (B(i, 0) * Fv + B(i, 1) * Fu);
  }
  const double A = rest.area;
  StretchingTerms out;
  out.energy = 0.5 * A * (k[0] * G00 * G00 + 2 * k[1] * G00 * G11 + k[2] * G11 * G11 +
                          2 * k[3] * G01 * G01);
  out.force = -A * (k[0] * G00 * g00 + k[1] * (G11 * g00 + G00 * g11) + k[2] * G11 * g11 +
                    2 * k[3] * G01 * g01);
  // Second derivatives of the strains are (scalar 3x3 block coefficient) * I.
  Eigen::Matrix3d H00, H11, H01;  // coefficient matrices over (i, j)
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      H00(i, j) = B(i, 0) * B(j, 0);
      H11(i, j) = B(i, 1) * B(j, 1);
      H01(i, j) = 0.5 * (B(i, 0) * B(j, 1) + B(i, 1) * B(j, 0));
    }
  const double p00 = definite ? std::max(G00, 0.0) : G00;
  const double p11 = definite ? std::max(G11, 0.0) : G11;
  const double p01 = definite ? 0.0 : G01;
  const Eigen::Matrix3d coeff = k[0] * p00 * H00 + k[1] * (p11 * H00 + p00 * H11) +
                                k[2] * p11 * H11 + 2 * k[3] * p01 * H01;
  Matrix9d hess = k[0] * g00 * g00.transpose() +
                  k[1] * (g00 * g11.transpose() + g11 * g00.transpose()) +
                  k[2] * g11 * g11.transpose() + 2 * k[3] * g01 * g01.transpose();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) hess.block<3, 3>(3 * i, 3 * j).diagonal().array() += coeff(i, j);
  out.jacobian = -A * hess;
  return out;
}

double StretchingForceBlocks(const Vector9d& x, const TriangleRest& rest, const Eigen::Vector4d& k,
                             bool definite, Vector9d* force, Eigen::Matrix3d jacobian[9]) {
  // Plain scalar code: this runs once per face per step.
  const Eigen::Matrix2d& D = rest.Dm_inv;
  double e1[3], e2[3], Fu[3], Fv[3];
  for (int r = 0; r < 3; ++r) {
    e1[r] = x[3 + r] - x[r];
    e2[r] = x[6 + r] - x[r];
    Fu[r] = e1[r] * D(0, 0) + e2[r] * D(1, 0);
    Fv[r] = e1[r] * D(0, 1) + e2[r] * D(1, 1);
  }
  // B(i, c): d F.col(c) / d x_i (scalar multiple of the identity).
  const double B[3][2] = {{-(D(0, 0) + D(1, 0)), -(D(0, 1) + D(1, 1))},
                          {D(0, 0), D(0, 1)},
                          {D(1, 0), D(1, 1)}};
  const double uu = Fu[0] * Fu[0] + Fu[1] * Fu[1] + Fu[2] * Fu[2];
  const double vv = Fv[0] * Fv[0] + Fv[1] * Fv[1] + Fv[2] * Fv[2];
  const double uv = Fu[0] * Fv[0] + Fu[1] * Fv[1] + Fu[2] * Fv[2];
  const double G00 = 0.5 * (uu - 1), G11 = 0.5 * (vv - 1), G01 = 0.5 * uv;
  const double A = rest.area;
  // f_i = -A (s_u B_i0 Fu + s_v B_i1 Fv + s_uv (B_i0 Fv + B_i1 Fu)), from dG/dx_i.
  const double su = k[0] * G00 + k[1] * G11, sv = k[1] * G00 + k[2] * G11, suv = k[3] * G01;
  for (int i = 0; i < 3; ++i) {
    const double cu = -A * (su * B[i][0] + suv * B[i][1]), cv = -A * (sv * B[i][1] + suv * B[i][0]);
    for (int r = 0; r < 3; ++r) (*force)[3 * i + r] = cu * Fu[r] + cv * Fv[r];
  }
  const double p00 = definite ? std::max(G00, 0.0) : G00;
  const double p11 = definite ? std::max(G11, 0.0) : G11;
  const double p01 = definite ? 0.0 : G01;
  const double hk3 = 0.5 * k[3];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const double a = B[i][0] * B[j][0], b = B[i][0] * B[j][1], c = B[i][1] * B[j][0],
                   d = B[i][1] * B[j][1];
      // Block = -A (cuu Fu Fu^T + cuv Fu Fv^T + cvu Fv Fu^T + cvv Fv Fv^T + diag I).
      const double cuu = -A * (k[0] * a + hk3 * d), cuv = -A * (k[1] * b + hk3 * c),
                   cvu = -A * (k[1] * c + hk3 * b), cvv = -A * (k[2] * d + hk3 * a);
      const double diag =
          -A * (k[0] * p00 * a + k[1] * (p11 * a + p00 * d) + k[2] * p11 * d + k[3] * p01 * (b + c));
      Eigen::Matrix3d& blk = jacobian[3 * i + j];
      for (int col = 0; col < 3; ++col) {
        const double wu = cuu * Fu[col] + cuv * Fv[col];  // multiplies Fu[row]
        const double wv = cvu * Fu[col] + cvv * Fv[col];  // multiplies Fv[row]
        for (int row = 0; row < 3; ++row) blk(row, col) = wu * Fu[row] + wv * Fv[row];
        blk(col, col) += diag;
      }
      if (j != i) jacobian[3 * j + i] = blk.transpose();
    }
  return 0.5 * A * (k[0] * G00 * G00 + 2 * k[1] * G00 * G11 + k[2] * G11 * G11 + 2 * k[3] * G01 * G01);
}

double DihedralAngle(const Vector12d& x, Vector12d* gradient) {
  const Eigen::Vector3d x0 = x.segment<3>(0), x1 = x.segment<3>(3), x2 = x.segment<3>(6),
                        x3 = x.segment<3>(9);
  const Eigen::Vector3d N0 = (x1 - x0).cross(x2 - x0);  // face (x0, x1, x2)
  const Eigen::Vector3d N1 = (x0 - x1).cross(x3 - x1);  // face (x1, x0, x3)
  const Eigen::Vector3d edge = x0 - x1;
  const double el = edge.norm();
  const double n0l = N0.norm(), n1l = N1.norm();
  if (el == 0 || n0l == 0 || n1l == 0) {
    if (gradient) gradient->setZero();
    return 0;
  }
  const Eigen::Vector3d n0 = N0 / n0l, n1 = N1 / n1l, e = edge / el;
  const double theta = std::atan2(e.dot(n0.cross(n1)), n0.dot(n1));
  if (gradient) {
    // Heights of the opposite vertices over the edge line and the barycentric weights of their
    // projections onto it (weight of x0, weight of x1).
    const Eigen::Vector3d d = x1 - x0;
    const double t2 = (x2 - x0).dot(d) / d.squaredNorm(), t3 = (x3 - x0).dot(d) / d.squaredNorm();
    // Heights (= 2 area / base) bounded below by 1e-3 |e|, as ArcSim's distance() does: a sliver
    // face's exact gradient grows as 1 / height (and the Gauss-Newton Jacobian as its square),
    // which one nearly collapsed face turns into a kick that blows the step up.
    const double h0 = std::max(n0l / el, kMinHingeHeight * el), h1 = std::max(n1l / el, kMinHingeHeight * el);
    gradient->segment<3>(0) = -((1 - t2) * n0 / h0 + (1 - t3) * n1 / h1);
    gradient->segment<3>(3) = -(t2 * n0 / h0 + t3 * n1 / h1);
    gradient->segment<3>(6) = n0 / h0;
    gradient->segment<3>(9) = n1 / h1;
  }
  return theta;
}

BendingTerms BendingForce(const Vector12d& x, double ke, double rest_length, double rest_area_sum,
                          double theta_rest) {
  Vector12d dtheta;
  const double theta = DihedralAngle(x, &dtheta);
  const double shape = rest_length * rest_length / (2 * rest_area_sum);
  const double c = ke * shape;
  BendingTerms out;
  out.energy = 0.25 * c * (theta - theta_rest) * (theta - theta_rest);
  out.force = -0.5 * c * (theta - theta_rest) * dtheta;
  out.jacobian = -0.5 * c * dtheta * dtheta.transpose();
  return out;
}

Vector9d WindForce(const Vector9d& x, const Vector9d& v, const Eigen::Vector3d& wind, double area,
                   double density, double drag) {
  const Eigen::Vector3d N =
      (x.segment<3>(3) - x.segment<3>(0)).cross(x.segment<3>(6) - x.segment<3>(0));
  const double nl = N.norm();
  Vector9d f = Vector9d::Zero();
  if (nl == 0) return f;
  const Eigen::Vector3d n = N / nl;
  const Eigen::Vector3d vface = (v.segment<3>(0) + v.segment<3>(3) + v.segment<3>(6)) / 3.0;
  const Eigen::Vector3d vrel = wind - vface;
  const double vn = n.dot(vrel);
  const Eigen::Vector3d force = density * area * std::abs(vn) * vn * n + drag * area * (vrel - vn * n);
  for (int i = 0; i < 3; ++i) f.segment<3>(3 * i) = force / 3.0;
  return f;
}

RepulsionTerms RepulsionForce(const Vector12d& x, double side, double thickness, double stiffness) {
  RepulsionTerms out;
  out.force.setZero();
  out.jacobian.setZero();
  const Eigen::Vector3d p = x.segment<3>(0), a = x.segment<3>(3), b = x.segment<3>(6),
                        c = x.segment<3>(9);
  const Eigen::Vector3d N = (b - a).cross(c - a);
  const double nn = N.squaredNorm();
  if (nn == 0) return out;
  const Eigen::Vector3d n = N / std::sqrt(nn);
  // Barycentrics of the projection of p onto the triangle's plane.
  const Eigen::Vector3d ap = p - a;
  const double wb = (ap).cross(c - a).dot(N) / nn;
  const double wc = (b - a).cross(ap).dot(N) / nn;
  const double wa = 1 - wb - wc;
  const double d = side * n.dot(ap);
  if (wa < 0 || wb < 0 || wc < 0 || d >= thickness) return out;
  Vector12d g;  // dd/dx, exact for the point-plane distance
  g.segment<3>(0) = side * n;
  g.segment<3>(3) = -side * wa * n;
  g.segment<3>(6) = -side * wb * n;
  g.segment<3>(9) = -side * wc * n;
  const double v = thickness - d;
  out.active = true;
  out.energy = stiffness * v * v * v / (6 * thickness);
  out.force = (stiffness * v * v / (2 * thickness)) * g;
  out.jacobian = -(stiffness * v / thickness) * g * g.transpose();
  return out;
}

}  // namespace clothwind::sim
