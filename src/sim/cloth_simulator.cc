#include "sim/cloth_simulator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <Eigen/LU>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "sim/cloth_forces.h"
#include "sim/crossing_resolver.h"
#include "sim/strain_limiter.h"
#include "sim/vertex_face_proximity.h"

namespace clothwind::sim {
namespace {

// A hinge: interior edge (x0, x1) with opposite vertices x2 (face (x0,x1,x2)) and x3
// (face (x1,x0,x3)), and its rest data.
struct Hinge {
  int v[4];
  double rest_length;
  double rest_area_sum;
  Eigen::Vector2d du;  // material-space edge direction (picks the bending table row)
  std::array<double, 5> bending_row;  // the table interpolated for du
  int block[16] = {};  // block index of (v[i], v[j]) in the system matrix
};

struct Face {
  int v[3];
  TriangleRest rest;
  int block[9] = {};
};

// A vertex moved back across a face it jumped through lands this fraction of the repulsion
// thickness from it: inside the repulsion's reach (so the next step pushes it gently further),
// with little penalty energy stored (1/8 of what the full thickness would store).
constexpr double kCrossingGapFraction = 0.5;

}  // namespace

struct ClothSimulator::Impl {
  Mesh mesh;
  Material material;
  SimOptions options;
  std::shared_ptr<const WindField> wind;

  int nv = 0;
  std::vector<Face> faces;
  std::vector<Hinge> hinges;
  Eigen::VectorXd mass;
  Eigen::VectorXd vertex_area;      // a third of the adjacent rest areas [m^2]
  std::vector<char> pinned;
  bool implicit_bending = true;
  Eigen::MatrixX3d x, v;
  double t = 0;
  long steps = 0;
  StepStats stats;
  std::string failure;  // why the state blew up ("" while it has not)
  double max_relative_air = 0;  // largest |wind - face velocity| of the last force evaluation [m/s]
  // The first step whose explicit wind was unstable (dt density |v_rel| / area weight, or the
  // tangential drag's dt drag / area weight, above 2): its step (-1: none since the state was
  // set), ratios and relative air speed, for the blow-up's message.
  long wind_unstable_step = -1;
  double wind_unstable_ratio = 0, wind_unstable_air = 0, drag_unstable_ratio = 0;

  // Records the step's explicit wind stability (see wind_unstable_step), after its forces.
  void CheckWindStability() {
    if (wind_unstable_step >= 0) return;
    const double ratio = options.dt * options.wind_density * max_relative_air / material.density;
    const double drag_ratio = options.dt * options.wind_drag / material.density;
    if (ratio > 2.0 || drag_ratio > 2.0) {
      wind_unstable_step = steps + 1;
      wind_unstable_ratio = ratio;
      wind_unstable_air = max_relative_air;
      drag_unstable_ratio = drag_ratio;
    }
  }

  // Block-sparse (3x3 blocks) symmetric system matrix with a fixed pattern, stored in full.
  std::vector<int> row_start;   // nv + 1
  std::vector<int> col;         // per block
  std::vector<int> diag_block;  // per vertex
  std::vector<Eigen::Matrix3d> J;  // force Jacobian blocks
  // Off-pattern blocks (repulsion pairs couple vertices that share no element), per step.
  struct ExtraBlock {
    int row, col;
    Eigen::Matrix3d J;
  };
  std::vector<ExtraBlock> extra;
  double repulsion_energy = 0;
  Eigen::VectorXd f, b, dv, r, z, p, q;
  std::vector<Eigen::Matrix3d> precond;

  std::unique_ptr<VertexFaceProximity> proximity;
  std::unique_ptr<StrainLimiter> limiter;
  std::unique_ptr<CrossingResolver> resolver;
  Eigen::MatrixX3d x_start;  // positions at the start of the step (for the crossing check)
  // True when the resolver's vertex-face candidates of the last step cover every pair within the
  // repulsion thickness at the current x (nothing moved since they were found): the next step's
  // proximity search then filters them instead of running its own grid.
  bool proximity_from_resolver = false;

  void Build();
  int BlockIndex(int i, int j) const;
  int BlockIndexInFace(int face, int i, int j) const { return faces[face].block[3 * i + j]; }
  void ComputeForces(bool with_jacobian, bool with_repulsion);
  void Solve();
  void CheckState();
  // Records `what` as the failure (naming the simulated time of step number `step` and the step's
  // stats) and throws it: the one blow-up error of Step, wherever the step finds the blow-up.
  [[noreturn]] void BlowUp(long step, const std::string& what);
  ClothEnergy Energy() const;
};

int ClothSimulator::Impl::BlockIndex(int i, int j) const {
  auto begin = col.begin() + row_start[i], end = col.begin() + row_start[i + 1];
  auto it = std::lower_bound(begin, end, j);
  if (it == end || *it != j) throw std::logic_error("ClothSimulator: block not in pattern");
  return static_cast<int>(it - col.begin());
}

void ClothSimulator::Impl::Build() {
  ValidateMesh(mesh, "ClothSimulator mesh");
  nv = static_cast<int>(mesh.V.rows());
  if (!(options.dt > 0) || !std::isfinite(options.dt))
    throw std::invalid_argument("SimOptions.dt must be finite and > 0, got " + std::to_string(options.dt));
  if (!options.gravity.allFinite()) throw std::invalid_argument("SimOptions.gravity must be finite");
  // Each check also refuses NaN and +inf (an infinite stiffness or density only failed later, as
  // a non-finite force naming neither).
  auto finite_at_least_0 = [](double x) { return x >= 0 && std::isfinite(x); };
  if (!finite_at_least_0(options.wind_density) || !finite_at_least_0(options.wind_drag))
    throw std::invalid_argument("SimOptions.wind_density and wind_drag must be finite and >= 0");
  if (!StrainLimitsAreValid(options.strain_min, options.strain_max))
    throw std::invalid_argument("SimOptions strain limits [" + std::to_string(options.strain_min) + ", " +
                                std::to_string(options.strain_max) + "] must satisfy " + kStrainLimitsRule);
  if ((options.strain_min > 0 || std::isfinite(options.strain_max)) && options.strain_limit_iterations < 1)
    throw std::invalid_argument("SimOptions.strain_limit_iterations must be >= 1 when a strain limit is set, got " +
                                std::to_string(options.strain_limit_iterations));
  // The global method's iterates are not monotone: with 5-10 at most the flag went unstable at
  // 10 m/s (docs/simulator.md, "Strain limiting"); the default 4 suits only the sweeps.
  if (options.strain_limit_method == StrainLimitMethod::kGlobal && options.strain_limit_iterations < 20)
    throw std::invalid_argument("SimOptions.strain_limit_iterations must be >= 20 with the global strain-limit "
                                "method (30 measured), got " + std::to_string(options.strain_limit_iterations));
  if (!(options.strain_limit_tolerance >= 0 && options.strain_limit_tolerance < 1))
    throw std::invalid_argument("SimOptions.strain_limit_tolerance must be in [0, 1), got " +
                                std::to_string(options.strain_limit_tolerance));
  if (!finite_at_least_0(options.repulsion_thickness) || !finite_at_least_0(options.collision_stiffness))
    throw std::invalid_argument("SimOptions.repulsion_thickness and collision_stiffness must be finite and >= 0");
  // The solve starts at dv = 0, whose relative residual is exactly 1: a tolerance of 1 or more
  // would end every solve before its first iteration, and the cloth would never move.
  if (!(options.cg_tolerance > 0 && options.cg_tolerance < 1) || options.cg_max_iterations < 1)
    throw std::invalid_argument("SimOptions.cg_tolerance must be in (0, 1) and cg_max_iterations >= 1, got " +
                                std::to_string(options.cg_tolerance) + " and " +
                                std::to_string(options.cg_max_iterations));
  if (!(options.max_speed > 0)) throw std::invalid_argument("SimOptions.max_speed must be > 0 [m/s]");
  if (!(material.density > 0) || material.stretching_samples.empty())
    throw std::invalid_argument("ClothSimulator: material is not initialised (use MakeMaterial/LoadArcSimMaterial)");
  pinned.assign(nv, 0);
  for (int h : options.handles) {
    if (h < 0 || h >= nv)
      throw std::invalid_argument("SimOptions.handles: vertex index " + std::to_string(h) +
                                  " out of range [0, " + std::to_string(nv) + ")");
    pinned[h] = 1;
  }

  // Faces, masses.
  const int nf = static_cast<int>(mesh.F.rows());
  faces.resize(nf);
  mass = Eigen::VectorXd::Zero(nv);
  vertex_area = Eigen::VectorXd::Zero(nv);
  for (int fi = 0; fi < nf; ++fi) {
    Face& face = faces[fi];
    for (int c = 0; c < 3; ++c) face.v[c] = mesh.F(fi, c);
    face.rest = MakeTriangleRest(mesh.U.row(face.v[0]), mesh.U.row(face.v[1]), mesh.U.row(face.v[2]));
    for (int c = 0; c < 3; ++c) vertex_area[face.v[c]] += face.rest.area / 3.0;
  }
  mass = material.density * vertex_area;  // > 0: ValidateMesh refused vertices in no face

  // Hinges from directed half-edges (each used once: ValidateMesh refused repeats).
  std::map<std::pair<int, int>, std::pair<int, int>> half;  // (a,b) -> (face, opposite vertex)
  for (int fi = 0; fi < nf; ++fi)
    for (int c = 0; c < 3; ++c) {
      const int a = faces[fi].v[c], b2 = faces[fi].v[(c + 1) % 3], o = faces[fi].v[(c + 2) % 3];
      half.emplace(std::make_pair(a, b2), std::make_pair(fi, o));
    }
  hinges.clear();
  for (const auto& [edge, fo] : half) {
    const int a = edge.first, b2 = edge.second;
    if (a > b2) continue;
    auto other = half.find({b2, a});
    if (other == half.end()) continue;  // boundary edge
    Hinge h;
    h.v[0] = a;
    h.v[1] = b2;
    h.v[2] = fo.second;
    h.v[3] = other->second.second;
    h.du = (mesh.U.row(b2) - mesh.U.row(a)).transpose();
    h.rest_length = h.du.norm();
    h.rest_area_sum = faces[fo.first].rest.area + faces[other->second.first].rest.area;
    h.bending_row = material.BendingRow(h.du);
    hinges.push_back(h);
  }

  // Block pattern: vertex pairs sharing a face or a hinge.
  std::vector<std::vector<int>> adj(nv);
  auto link = [&](int i, int j) { adj[i].push_back(j); };
  for (int i = 0; i < nv; ++i) link(i, i);
  for (const Face& face : faces)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) link(face.v[i], face.v[j]);
  implicit_bending = options.bending_solve == BendingSolve::kImplicit;
  if (options.bending_solve == BendingSolve::kAuto) {
    // Gershgorin bound of h^2 M^-1 K_bend at rest: per hinge, K = c g g^T with c = ke shape / 2;
    // row i of M^-1 K is bounded by c |g_i| sum_j |g_j| / m_i.
    double bound = 0;
    std::vector<double> row_sum(nv, 0.0);
    for (const Hinge& h : hinges) {
      Vector12d xh, g;
      for (int c = 0; c < 4; ++c) xh.segment<3>(3 * c) = mesh.V.row(h.v[c]).transpose();
      // Rest (flat) geometry from U gives the same gradient norms as any isometric placement.
      for (int c = 0; c < 4; ++c) xh.segment<3>(3 * c) << mesh.U(h.v[c], 0), mesh.U(h.v[c], 1), 0;
      DihedralAngle(xh, &g);
      const double ke = *std::max_element(h.bending_row.begin(), h.bending_row.end());
      const double c_half = 0.5 * ke * h.rest_length * h.rest_length / (2 * h.rest_area_sum);
      double gsum = 0;
      for (int c = 0; c < 4; ++c) gsum += g.segment<3>(3 * c).norm();
      for (int c = 0; c < 4; ++c) row_sum[h.v[c]] += c_half * g.segment<3>(3 * c).norm() * gsum;
    }
    for (int i = 0; i < nv; ++i) bound = std::max(bound, options.dt * options.dt * row_sum[i] / mass[i]);
    implicit_bending = bound > 0.5;
  }
  stats.implicit_bending = implicit_bending;
  if (implicit_bending)
    for (const Hinge& h : hinges) {
      link(h.v[2], h.v[3]);
      link(h.v[3], h.v[2]);
    }
  row_start.assign(nv + 1, 0);
  col.clear();
  for (int i = 0; i < nv; ++i) {
    std::sort(adj[i].begin(), adj[i].end());
    adj[i].erase(std::unique(adj[i].begin(), adj[i].end()), adj[i].end());
    row_start[i] = static_cast<int>(col.size());
    col.insert(col.end(), adj[i].begin(), adj[i].end());
  }
  row_start[nv] = static_cast<int>(col.size());
  diag_block.resize(nv);
  for (int i = 0; i < nv; ++i) diag_block[i] = BlockIndex(i, i);
  for (Face& face : faces)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) face.block[3 * i + j] = BlockIndex(face.v[i], face.v[j]);
  for (Hinge& h : hinges)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        h.block[4 * i + j] = (implicit_bending || i + j != 5 || i == j)
                                 ? BlockIndex(h.v[i], h.v[j])
                                 : -1;
  J.assign(col.size(), Eigen::Matrix3d::Zero());
  precond.assign(nv, Eigen::Matrix3d::Zero());
  const int n3 = 3 * nv;
  f.setZero(n3);
  b.setZero(n3);
  dv.setZero(n3);
  r.setZero(n3);
  z.setZero(n3);
  p.setZero(n3);
  q.setZero(n3);

  x = mesh.V;
  v = Eigen::MatrixX3d::Zero(nv, 3);
  double mean_edge = 0, longest_edge = 0;
  for (const Face& face : faces)
    for (int c = 0; c < 3; ++c) {
      const double edge = (mesh.U.row(face.v[c]) - mesh.U.row(face.v[(c + 1) % 3])).norm();
      mean_edge += edge;
      longest_edge = std::max(longest_edge, edge);
    }
  mean_edge /= 3.0 * faces.size();
  // The proximity grid's cell: the mean rest edge, raised to an eighth of the longest, so that
  // every face of the unstretched mesh spans at most about 8 cells. The grid skips a face spanning
  // more than 32 (an exploded state, where looping over its cells would hang): sized from the
  // mean edge alone, a mesh whose edges differ a hundredfold (a coarse panel beside a fine one)
  // had its large faces skipped, and nothing repelled from them.
  proximity = std::make_unique<VertexFaceProximity>(mesh.F, nv, std::max(mean_edge, longest_edge / 8));
  limiter = std::make_unique<StrainLimiter>(mesh, mass, pinned);
  Eigen::VectorXd inverse_mass(nv);
  for (int i = 0; i < nv; ++i) inverse_mass[i] = pinned[i] ? 0.0 : 1.0 / mass[i];
  resolver = std::make_unique<CrossingResolver>(mesh.F, inverse_mass);
  x_start = x;
}

void ClothSimulator::Impl::ComputeForces(bool with_jacobian, bool with_repulsion) {
  f.setZero();
  max_relative_air = 0;
  if (with_jacobian)
    for (auto& blk : J) blk.setZero();
  auto xv = [&](int i) { return x.row(i).transpose(); };
  // Gravity.
  for (int i = 0; i < nv; ++i) f.segment<3>(3 * i) += mass[i] * options.gravity;
  // Stretching and wind, per face.
  for (const Face& face : faces) {
    Vector9d xf, vf;
    for (int c = 0; c < 3; ++c) {
      xf.segment<3>(3 * c) = xv(face.v[c]);
      vf.segment<3>(3 * c) = v.row(face.v[c]).transpose();
    }
    const Eigen::Vector4d k = material.StretchingStiffness(GreenStrain(xf, face.rest));
    Vector9d fe;
    Eigen::Matrix3d blocks[9];
    StretchingForceBlocks(xf, face.rest, k, /*definite=*/true, &fe, blocks);
    if (options.wind_density > 0 || options.wind_drag > 0) {
      Eigen::Vector3d air = Eigen::Vector3d::Zero();
      if (wind) air = wind->Velocity((xf.segment<3>(0) + xf.segment<3>(3) + xf.segment<3>(6)) / 3.0, t);
      fe += WindForce(xf, vf, air, face.rest.area, options.wind_density, options.wind_drag);
      max_relative_air = std::max(
          max_relative_air, (air - (vf.segment<3>(0) + vf.segment<3>(3) + vf.segment<3>(6)) / 3.0).norm());
    }
    for (int c = 0; c < 3; ++c) f.segment<3>(3 * face.v[c]) += fe.segment<3>(3 * c);
    if (with_jacobian)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) J[face.block[3 * i + j]] += blocks[3 * i + j];
  }
  // Bending, per hinge (ArcSim's bending_force, inlined so the dihedral is evaluated once).
  for (const Hinge& h : hinges) {
    Vector12d xh, dtheta;
    for (int c = 0; c < 4; ++c) xh.segment<3>(3 * c) = xv(h.v[c]);
    const double theta = DihedralAngle(xh, &dtheta);
    const double curvature = std::abs(theta) * h.rest_length / h.rest_area_sum;
    const double ke = Material::BendingStiffnessFromRow(curvature, h.bending_row);
    const double c_half = 0.5 * ke * h.rest_length * h.rest_length / (2 * h.rest_area_sum);
    for (int c = 0; c < 4; ++c) f.segment<3>(3 * h.v[c]) -= c_half * theta * dtheta.segment<3>(3 * c);
    if (with_jacobian && implicit_bending)
      for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d gi = -c_half * dtheta.segment<3>(3 * i);
        for (int j = i; j < 4; ++j) {
          const Eigen::Matrix3d blk = gi * dtheta.segment<3>(3 * j).transpose();
          J[h.block[4 * i + j]] += blk;
          if (j != i) J[h.block[4 * j + i]] += blk.transpose();
        }
      }
  }
  // Vertex-face repulsion (ArcSim's proximity constraints), implicit with its full Gauss-Newton
  // Jacobian: blocks outside the fixed pattern go to `extra`.
  stats.repulsion_pairs = 0;
  extra.clear();
  repulsion_energy = 0;
  if (with_repulsion) {
    for (const auto& pr : proximity->pairs()) {
      Vector12d xr;
      xr.segment<3>(0) = xv(pr.vertex);
      for (int c = 0; c < 3; ++c) xr.segment<3>(3 + 3 * c) = xv(mesh.F(pr.face, c));
      const double area = std::min(vertex_area[pr.vertex], faces[pr.face].rest.area);
      const double stiffness = options.collision_stiffness * area;
      const RepulsionTerms rt = RepulsionForce(xr, pr.side, options.repulsion_thickness, stiffness);
      if (!rt.active) continue;
      ++stats.repulsion_pairs;
      repulsion_energy += rt.energy;
      const int ids[4] = {pr.vertex, mesh.F(pr.face, 0), mesh.F(pr.face, 1), mesh.F(pr.face, 2)};
      for (int c = 0; c < 4; ++c) f.segment<3>(3 * ids[c]) += rt.force.segment<3>(3 * c);
      if (!with_jacobian) continue;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
          const Eigen::Matrix3d blk = rt.jacobian.block<3, 3>(3 * i, 3 * j);
          if (i == j) {
            J[diag_block[ids[i]]] += blk;
          } else if (i == 0 || j == 0) {  // vertex-to-face-vertex: never in the pattern
            extra.push_back({ids[i], ids[j], blk});
          } else {  // two vertices of the same face
            J[BlockIndexInFace(pr.face, i - 1, j - 1)] += blk;
          }
        }
    }
  }
}

void ClothSimulator::Impl::Solve() {
  const double h = options.dt;
  const double hk = h * (h + material.damping);
  // A = M - h (h + gamma) J (applied blockwise, never stored);  b = h (f + (h + gamma) J v).
  for (int i = 0; i < nv; ++i) {
    Eigen::Vector3d Jv = Eigen::Vector3d::Zero();
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) Jv.noalias() += J[k] * v.row(col[k]).transpose();
    b.segment<3>(3 * i) = h * (f.segment<3>(3 * i) + (h + material.damping) * Jv);
  }
  for (const ExtraBlock& e : extra)
    b.segment<3>(3 * e.row).noalias() += h * (h + material.damping) * (e.J * v.row(e.col).transpose());
  for (int i = 0; i < nv; ++i) {
    if (pinned[i]) {
      b.segment<3>(3 * i).setZero();
      precond[i].setZero();
    } else {
      Eigen::Matrix3d D = -hk * J[diag_block[i]];
      D.diagonal().array() += mass[i];
      precond[i] = D.inverse();
    }
  }
  // The hot loop of the step: plain scalar code over the contiguous column-major 3x3 blocks.
  const double* Jd = J.empty() ? nullptr : J[0].data();
  const int* cols = col.data();
  const int* starts = row_start.data();
  auto multiply = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    const double* x = in.data();
    double* y = out.data();
    for (int i = 0; i < nv; ++i) {
      double s0 = 0, s1 = 0, s2 = 0;
#ifdef __SSE2__
      // Rows 0 and 1 of each block as one packed pair (the same operations in the same order as
      // the scalar code below, so the results are bit-identical): ~40 % fewer instructions.
      __m128d s01 = _mm_setzero_pd();
      for (int k = starts[i]; k < starts[i + 1]; ++k) {
        const double* a = Jd + 9 * k;
        const double* p = x + 3 * cols[k];
        const __m128d t = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_loadu_pd(a), _mm_set1_pd(p[0])),
                                                _mm_mul_pd(_mm_loadu_pd(a + 3), _mm_set1_pd(p[1]))),
                                     _mm_mul_pd(_mm_loadu_pd(a + 6), _mm_set1_pd(p[2])));
        s01 = _mm_add_pd(s01, t);
        s2 += a[2] * p[0] + a[5] * p[1] + a[8] * p[2];
      }
      s0 = _mm_cvtsd_f64(s01);
      s1 = _mm_cvtsd_f64(_mm_unpackhi_pd(s01, s01));
#else
      for (int k = starts[i]; k < starts[i + 1]; ++k) {
        const double* a = Jd + 9 * k;
        const double* p = x + 3 * cols[k];
        s0 += a[0] * p[0] + a[3] * p[1] + a[6] * p[2];
        s1 += a[1] * p[0] + a[4] * p[1] + a[7] * p[2];
        s2 += a[2] * p[0] + a[5] * p[1] + a[8] * p[2];
      }
#endif
      const double m = mass[i];
      y[3 * i] = m * x[3 * i] - hk * s0;
      y[3 * i + 1] = m * x[3 * i + 1] - hk * s1;
      y[3 * i + 2] = m * x[3 * i + 2] - hk * s2;
    }
    for (const ExtraBlock& e : extra) out.segment<3>(3 * e.row).noalias() -= hk * (e.J * in.segment<3>(3 * e.col));
    for (int i = 0; i < nv; ++i)
      if (pinned[i]) y[3 * i] = y[3 * i + 1] = y[3 * i + 2] = 0;
  };
  // Preconditioned conjugate gradients, warm-started with the previous step's dv.
  for (int i = 0; i < nv; ++i)
    if (pinned[i]) dv.segment<3>(3 * i).setZero();
  // A non-finite |b| makes every relative residual NaN, and `rel > tol` is false for NaN: the
  // loop below would end before its first iteration and leave dv = 0, a cloth that never moves
  // (a scene with gravity 1e200 ran to the end, exit 0, the cloth frozen). Finite forces can
  // still overflow the norm's sum of squares, so the norm is what is checked.
  const double b_norm = b.norm();
  if (!std::isfinite(b_norm)) {
    stats.cg_iterations = 0;
    stats.cg_relative_residual = std::numeric_limits<double>::quiet_NaN();
    char what[512];
    int bad = -1;
    for (int i = 0; i < nv && bad < 0; ++i)
      if (!pinned[i] && !f.segment<3>(3 * i).allFinite()) bad = i;
    if (bad >= 0) {
      std::snprintf(what, sizeof(what), "vertex %d has a non-finite force (wind field or element forces)", bad);
    } else {
      for (int i = 0; i < nv && bad < 0; ++i)
        if (!b.segment<3>(3 * i).allFinite()) bad = i;
      if (bad >= 0)
        std::snprintf(what, sizeof(what),
                      "the linear solve's right-hand side h (f + (h + damping) K v) is not finite at vertex %d "
                      "(stiffness, damping or velocity beyond double range)", bad);
      else
        std::snprintf(what, sizeof(what),
                      "the linear solve's right-hand side h (f + (h + damping) K v) has a norm beyond double "
                      "range (largest entry %.3g N s): gravity, density, wind or stiffness far out of range",
                      b.cwiseAbs().maxCoeff());
    }
    BlowUp(steps + 1, what);
  }
  multiply(dv, q);
  r = b - q;
  const double bnorm = std::max(b_norm, 1e-300);
  auto precondition = [&]() {
    for (int i = 0; i < nv; ++i) z.segment<3>(3 * i) = precond[i] * r.segment<3>(3 * i);
  };
  precondition();
  p = z;
  double rz = r.dot(z);
  int it = 0;
  double rel = r.norm() / bnorm;
  // NaN compares false both ways: without this check a NaN residual would end the solve as if
  // it had converged, with whatever dv it had.
  auto check_finite = [&](double value) {
    if (std::isfinite(value)) return;
    stats.cg_iterations = it;
    stats.cg_relative_residual = rel;
    char what[256];
    std::snprintf(what, sizeof(what),
                  "the linear solve's residual became non-finite after %d CG iterations (the system matrix or "
                  "the right-hand side is beyond double range)",
                  it);
    BlowUp(steps + 1, what);
  };
  check_finite(rel);
  while (rel > options.cg_tolerance && it < options.cg_max_iterations) {
    multiply(p, q);
    const double pq = p.dot(q);
    check_finite(pq);
    if (!(pq > 0)) break;  // not positive definite along p (compressed stretching): stop here
    const double alpha = rz / pq;
    dv += alpha * p;
    r -= alpha * q;
    ++it;
    rel = r.norm() / bnorm;
    check_finite(rel);
    if (rel <= options.cg_tolerance) break;
    precondition();
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  stats.cg_iterations = it;
  stats.cg_relative_residual = rel;
  // Worse than no step at all (dv = 0 has residual 1): the solve diverged, and the step it would
  // take is noise (an area weight far below the forces' scale). Accepted, it surfaced only later
  // as a vertex too fast, naming no cause.
  if (rel > 1.0) {
    char what[200];
    std::snprintf(what, sizeof(what),
                  "the linear solve diverged: relative residual %.3g after %d CG iterations (masses far below the "
                  "forces' scale: area weight, wind or stiffness out of range for this time step)",
                  rel, it);
    BlowUp(steps + 1, what);
  }
}

// Records (failure) and throws when the state has blown up: non-finite, or faster than
// max_speed. One pass over x and v, negligible next to a step.
void ClothSimulator::Impl::CheckState() {
  const double max_speed2 = options.max_speed * options.max_speed;
  // Non-finite forces first: a free vertex's already stopped Solve (its right-hand side), but a
  // pinned vertex's never reaches the solve (its row is zeroed) and would leave x and v finite.
  const bool forces_finite = f.allFinite();
  for (int i = 0; i < nv; ++i) {
    const double speed2 = v.row(i).squaredNorm();
    const bool force_finite = forces_finite || f.segment<3>(3 * i).allFinite();
    const bool finite = x.row(i).allFinite() && v.row(i).allFinite();
    if (force_finite && finite && speed2 <= max_speed2) continue;
    char what[512];
    if (!force_finite)
      std::snprintf(what, sizeof(what), "vertex %d has a non-finite force (wind field or element forces)", i);
    else if (!finite)
      std::snprintf(what, sizeof(what), "vertex %d has a non-finite %s", i,
                    x.row(i).allFinite() ? "velocity" : "position");
    else
      std::snprintf(what, sizeof(what), "vertex %d moves at %.4g m/s (more than SimOptions.max_speed = %g m/s)",
                    i, std::sqrt(speed2), options.max_speed);
    BlowUp(steps, what);
  }
}

void ClothSimulator::Impl::BlowUp(long step, const std::string& what) {
  char tail[512];
  std::snprintf(tail, sizeof(tail),
                "; that step: %d CG iterations (relative residual %.3g), %d strain-limited faces, "
                "%d repulsion pairs",
                stats.cg_iterations, stats.cg_relative_residual, stats.strain_limited_faces, stats.repulsion_pairs);
  char head[128];
  std::snprintf(head, sizeof(head), "ClothSimulator: the simulation blew up at t = %.4f s (step %ld): ",
                step * options.dt, step);
  // The wind force is explicit (no Jacobian, as ArcSim's): it damps a face's motion relative to
  // the air at a rate ~ density |v_rel| / area weight, which a step longer than about twice its
  // inverse overshoots (area weight 0.02 kg/m^2 at 10 m/s and 5 ms blew up at step 4). Said when
  // it applies, since the vertex that ends up too fast names no cause.
  std::string why;
  if (wind_unstable_step >= 0) {
    char hint[360];
    if (drag_unstable_ratio > 2.0) {  // the drag holds at any air speed: named first
      std::snprintf(hint, sizeof(hint),
                    "; the explicit wind drag was unstable from step %ld: dt * drag / area weight = %.3g > 2 "
                    "(drag %.3g kg/(m^2 s), %.3g kg/m^2, dt %.3g s): a smaller drag, a heavier cloth or a shorter "
                    "step (more frame_steps) holds it",
                    wind_unstable_step, drag_unstable_ratio, options.wind_drag, material.density, options.dt);
    } else {
      std::snprintf(hint, sizeof(hint),
                    "; the explicit wind force was unstable from step %ld: dt * wind density * |wind - cloth| / "
                    "area weight = %.3g > 2 (%.3g m/s, %.3g kg/m^2, dt %.3g s): a heavier cloth, a weaker wind or a "
                    "shorter step (more frame_steps) holds it",
                    wind_unstable_step, wind_unstable_ratio, wind_unstable_air, material.density, options.dt);
    }
    why = hint;
  }
  failure = std::string(head) + what + tail + why;
  throw std::runtime_error(failure);
}

ClothEnergy ClothSimulator::Impl::Energy() const {
  ClothEnergy e;
  for (int i = 0; i < nv; ++i) {
    e.kinetic += 0.5 * mass[i] * v.row(i).squaredNorm();
    e.gravitational -= mass[i] * options.gravity.dot(x.row(i).transpose());
  }
  for (const Face& face : faces) {
    Vector9d xf;
    for (int c = 0; c < 3; ++c) xf.segment<3>(3 * c) = x.row(face.v[c]).transpose();
    const Eigen::Matrix2d G = GreenStrain(xf, face.rest);
    const Eigen::Vector4d k = material.StretchingStiffness(G);
    e.stretching += 0.5 * face.rest.area *
                    (k[0] * G(0, 0) * G(0, 0) + 2 * k[1] * G(0, 0) * G(1, 1) + k[2] * G(1, 1) * G(1, 1) +
                     2 * k[3] * G(0, 1) * G(0, 1));
  }
  for (const Hinge& h : hinges) {
    Vector12d xh;
    for (int c = 0; c < 4; ++c) xh.segment<3>(3 * c) = x.row(h.v[c]).transpose();
    const double theta = DihedralAngle(xh);
    const double ke = Material::BendingStiffnessFromRow(std::abs(theta) * h.rest_length / h.rest_area_sum, h.bending_row);
    e.bending += 0.25 * ke * h.rest_length * h.rest_length / (2 * h.rest_area_sum) * theta * theta;
  }
  e.repulsion = repulsion_energy;
  return e;
}

ClothSimulator::ClothSimulator(Mesh mesh, Material material, SimOptions options,
                               std::shared_ptr<const WindField> wind)
    : impl_(std::make_unique<Impl>()) {
  impl_->mesh = std::move(mesh);
  impl_->material = std::move(material);
  impl_->options = std::move(options);
  impl_->wind = std::move(wind);
  impl_->Build();
}

ClothSimulator::~ClothSimulator() = default;
ClothSimulator::ClothSimulator(ClothSimulator&&) noexcept = default;
ClothSimulator& ClothSimulator::operator=(ClothSimulator&&) noexcept = default;

void ClothSimulator::Step() {
  Impl& s = *impl_;
  if (!s.failure.empty()) throw std::runtime_error(s.failure + " (stepped again after that)");
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  const double h = s.options.dt;
  const bool repel = s.options.self_collision && s.options.repulsion_thickness > 0 &&
                     s.options.collision_stiffness > 0;
  const auto t0 = Clock::now();
  if (repel) s.x_start = s.x;
  if (repel && s.proximity_from_resolver)
    s.proximity->UpdateFromCandidates(s.x, s.options.repulsion_thickness, s.resolver->vertex_face_candidates());
  else if (repel)
    s.proximity->Update(s.x, s.options.repulsion_thickness);
  s.proximity_from_resolver = false;
  const auto t1 = Clock::now();
  s.stats.strain_limited_faces = 0;  // (this step's, should the solve fail before the limiter)
  s.stats.strain_limit_sweeps = 0;
  s.stats.strain_limit_excess = 0;
  s.stats.strain_limit_converged = true;
  s.stats.crossings_resolved = 0;
  s.ComputeForces(/*with_jacobian=*/true, repel);
  // Here, not in ComputeForces: Forces() and Energy() of a state that never steps set it too.
  s.CheckWindStability();
  const auto t2 = Clock::now();
  s.Solve();
  for (int i = 0; i < s.nv; ++i) {
    if (s.pinned[i]) {
      s.v.row(i).setZero();
      continue;
    }
    s.v.row(i) += s.dv.segment<3>(3 * i).transpose();
    s.x.row(i) += h * s.v.row(i);
  }
  const auto t3 = Clock::now();
  s.stats.strain_limited_faces = 0;
  s.stats.strain_limit_sweeps = 0;
  s.stats.strain_limit_excess = 0;
  s.stats.strain_limit_converged = true;
  if (s.options.strain_min > 0 || std::isfinite(s.options.strain_max)) {
    StrainLimitSettings limits;
    limits.min = s.options.strain_min;
    limits.max = s.options.strain_max;
    limits.tolerance = s.options.strain_limit_tolerance;
    limits.max_sweeps = s.options.strain_limit_iterations;
    limits.method = s.options.strain_limit_method;
    const StrainLimitResult r = s.limiter->Project(limits, h, &s.x, &s.v);
    s.stats.strain_limited_faces = r.initially_violated;
    s.stats.strain_limit_sweeps = r.sweeps;
    s.stats.strain_limit_excess = r.excess;
    s.stats.strain_limit_converged = r.converged;
  }
  // Vertices that jumped through a face during the step go back to their side (see
  // crossing_resolver.h): the repulsion alone lets fast folds pass through.
  s.stats.crossings_resolved = 0;
  if (repel && s.options.crossing_sweeps > 0) {
    // Reach = the repulsion thickness, so the candidates also serve the next step's proximity
    // search, unless a correction has moved vertices since they were found.
    s.stats.crossings_resolved = s.resolver->Resolve(s.x_start, kCrossingGapFraction * s.options.repulsion_thickness,
                                                     s.options.repulsion_thickness, s.options.crossing_sweeps, &s.x, &s.v);
    s.proximity_from_resolver = s.stats.crossings_resolved == 0 && s.x.allFinite();
  }
  const auto t4 = Clock::now();
  s.stats.seconds_proximity = seconds(t0, t1);
  s.stats.seconds_forces = seconds(t1, t2);
  s.stats.seconds_solve = seconds(t2, t3);
  s.stats.seconds_strain_limit = seconds(t3, t4);
  ++s.steps;
  s.t = s.steps * h;
  s.CheckState();
}

double ClothSimulator::time() const { return impl_->t; }
const Eigen::MatrixX3d& ClothSimulator::positions() const { return impl_->x; }
const Eigen::MatrixX3d& ClothSimulator::velocities() const { return impl_->v; }

void ClothSimulator::SetState(const Eigen::MatrixX3d& positions, const Eigen::MatrixX3d& velocities) {
  Impl& s = *impl_;
  if (positions.rows() != s.nv || velocities.rows() != s.nv)
    throw std::invalid_argument("ClothSimulator::SetState: expected " + std::to_string(s.nv) +
                                " rows of positions and velocities");
  if (!positions.allFinite() || !velocities.allFinite())
    throw std::invalid_argument("ClothSimulator::SetState: non-finite positions or velocities");
  s.x = positions;
  s.v = velocities;
  for (int i = 0; i < s.nv; ++i)
    if (s.pinned[i]) s.v.row(i).setZero();
  s.dv.setZero();
  s.failure.clear();
  s.wind_unstable_step = -1;  // the new state's own stability: a hint of the old one named a gone wind
  s.proximity_from_resolver = false;  // the resolver's candidates were for the old positions
}

void ClothSimulator::set_wind(std::shared_ptr<const WindField> wind) { impl_->wind = std::move(wind); }
const Mesh& ClothSimulator::mesh() const { return impl_->mesh; }
const Material& ClothSimulator::material() const { return impl_->material; }
const SimOptions& ClothSimulator::options() const { return impl_->options; }
const Eigen::VectorXd& ClothSimulator::masses() const { return impl_->mass; }
ClothEnergy ClothSimulator::Energy() const {
  Forces();  // refreshes the repulsion pairs and their energy at the current state
  return impl_->Energy();
}

Eigen::MatrixX3d ClothSimulator::ForceJacobianTimes(const Eigen::MatrixX3d& dx) const {
  Impl& s = *impl_;
  if (dx.rows() != s.nv) throw std::invalid_argument("ForceJacobianTimes: expected " + std::to_string(s.nv) + " rows");
  const bool repel = s.options.self_collision && s.options.repulsion_thickness > 0 &&
                     s.options.collision_stiffness > 0;
  const StepStats kept = s.stats;
  if (repel) s.proximity->Update(s.x, s.options.repulsion_thickness);
  s.ComputeForces(/*with_jacobian=*/true, repel);
  s.stats = kept;
  // The same blocks the step's conjugate gradients multiply by (Solve's pattern and side list).
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(s.nv, 3);
  for (int i = 0; i < s.nv; ++i)
    for (int k = s.row_start[i]; k < s.row_start[i + 1]; ++k)
      out.row(i) += (s.J[k] * dx.row(s.col[k]).transpose()).transpose();
  for (const auto& e : s.extra) out.row(e.row) += (e.J * dx.row(e.col).transpose()).transpose();
  return out;
}

Eigen::MatrixX3d ClothSimulator::Forces() const {
  Impl& s = *impl_;
  const bool repel = s.options.self_collision && s.options.repulsion_thickness > 0 &&
                     s.options.collision_stiffness > 0;
  const StepStats kept = s.stats;  // last_step_stats() describes the last Step, not this call
  if (repel) s.proximity->Update(s.x, s.options.repulsion_thickness);
  s.ComputeForces(/*with_jacobian=*/false, repel);
  s.stats = kept;
  Eigen::MatrixX3d out(s.nv, 3);
  for (int i = 0; i < s.nv; ++i) out.row(i) = s.f.segment<3>(3 * i).transpose();
  return out;
}

const StepStats& ClothSimulator::last_step_stats() const { return impl_->stats; }

}  // namespace clothwind::sim
