#include "render/embree_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace clothwind::render {

namespace {
// Embree reports errors through a C callback (throwing across it is undefined), so errors are
// read back with rtcGetDeviceError after each batch of calls.
void CheckDevice(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error ") + std::to_string(e) + " in " + what);
}
constexpr float kPoleRadius = 0.035f;  // [m]
constexpr float kGroundHalfSize = 500.0f;  // [m]
}  // namespace

EmbreeScene::EmbreeScene(const RenderParams& p) {
  // One build thread: frames are rendered many at a time by the caller's threads, and a
  // 1000-vertex refit takes microseconds.
  device_ = rtcNewDevice("threads=1");
  if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  cloth_scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(cloth_scene_, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(cloth_scene_, RTC_BUILD_QUALITY_LOW);
  lift_ = static_cast<float>(p.mesh_height);
  const float w = static_cast<float>(p.mesh_width);
  const float h = static_cast<float>(p.MeshRestHeight());
  if (p.scene == SceneKind::kFlag) {
    // The pole touches the hoist edge (on the z axis) with its surface.
    const float top = lift_ + h + 0.12f;
    AddCylinder(Eigen::Vector3f(-kPoleRadius, 0, 0), Eigen::Vector3f(-kPoleRadius, 0, top),
                kPoleRadius);
    AddSphere(Eigen::Vector3f(-kPoleRadius, 0, top + 0.04f), 0.065f);
  } else {
    // A rod along the cloth's top edge (in the y-z plane at x = 0), on two posts.
    const float r = 0.015f, top = lift_ + h;
    AddCylinder(Eigen::Vector3f(0, -0.15f, top + r), Eigen::Vector3f(0, w + 0.15f, top + r), r);
    AddCylinder(Eigen::Vector3f(0, -0.15f, 0), Eigen::Vector3f(0, -0.15f, top + 2 * r), 0.025f);
    AddCylinder(Eigen::Vector3f(0, w + 0.15f, 0), Eigen::Vector3f(0, w + 0.15f, top + 2 * r),
                0.025f);
  }
  AddGround();
  rtcCommitScene(scene_);
  CheckDevice(device_, "building the static scene");
}

EmbreeScene::~EmbreeScene() {
  if (cloth_) rtcReleaseGeometry(cloth_);
  if (cloth_scene_) rtcReleaseScene(cloth_scene_);
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::AddCylinder(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float radius) {
  constexpr int kSegments = 16;
  const Eigen::Vector3f axis = (b - a).normalized();
  const Eigen::Vector3f helper =
      std::abs(axis.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f e1 = axis.cross(helper).normalized(), e2 = axis.cross(e1);
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 2 * kSegments));
  unsigned* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2 * kSegments));
  // Circumscribe the circle so the flat facets never cut inside the true radius.
  const float rr = radius / std::cos(static_cast<float>(M_PI) / kSegments);
  for (int i = 0; i < kSegments; ++i) {
    const float ang = 2.0f * static_cast<float>(M_PI) * i / kSegments;
    const Eigen::Vector3f off = rr * (std::cos(ang) * e1 + std::sin(ang) * e2);
    const Eigen::Vector3f p0 = a + off, p1 = b + off;
    for (int k = 0; k < 3; ++k) {
      vb[3 * i + k] = p0[k];
      vb[3 * (kSegments + i) + k] = p1[k];
    }
    const unsigned i0 = i, i1 = (i + 1) % kSegments;
    unsigned* f = ib + 6 * i;
    f[0] = i0; f[1] = i1; f[2] = kSegments + i1;
    f[3] = i0; f[4] = kSegments + i1; f[5] = kSegments + i0;
  }
  rtcCommitGeometry(g);
  const unsigned id = rtcAttachGeometry(scene_, g);
  rtcReleaseGeometry(g);
  cylinders_.push_back({id, a, axis});
}

void EmbreeScene::AddSphere(const Eigen::Vector3f& c, float radius) {
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
  vb[0] = c.x(); vb[1] = c.y(); vb[2] = c.z(); vb[3] = radius;
  rtcCommitGeometry(g);
  sphere_id_ = rtcAttachGeometry(scene_, g);
  rtcReleaseGeometry(g);
}

void EmbreeScene::AddGround() {
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4));
  unsigned* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2));
  const float s = kGroundHalfSize;
  const float corners[4][2] = {{-s, -s}, {s, -s}, {s, s}, {-s, s}};
  for (int i = 0; i < 4; ++i) {
    vb[3 * i] = corners[i][0];
    vb[3 * i + 1] = corners[i][1];
    vb[3 * i + 2] = 0.0f;
  }
  ib[0] = 0; ib[1] = 1; ib[2] = 2; ib[3] = 0; ib[4] = 2; ib[5] = 3;
  rtcCommitGeometry(g);
  ground_id_ = rtcAttachGeometry(scene_, g);
  rtcReleaseGeometry(g);
}

void EmbreeScene::SetCloth(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                           const Eigen::MatrixXd& UV) {
  if (V.cols() != 3 || V.rows() < 3)
    throw std::invalid_argument("SetCloth: V must be #V by 3 with #V >= 3, got " +
                                std::to_string(V.rows()) + "x" + std::to_string(V.cols()));
  if (F.cols() != 3 || F.rows() < 1)
    throw std::invalid_argument("SetCloth: F must be #F by 3 with #F >= 1, got " +
                                std::to_string(F.rows()) + "x" + std::to_string(F.cols()));
  if (UV.rows() != V.rows() || UV.cols() != 2)
    throw std::invalid_argument("SetCloth: UV must be #V by 2 (" + std::to_string(V.rows()) +
                                "x2), got " + std::to_string(UV.rows()) + "x" +
                                std::to_string(UV.cols()));
  const size_t nv = V.rows(), nf = F.rows();
  bool same_faces = cloth_ && faces_.size() == 3 * nf && positions_.size() == nv;
  if (same_faces) {
    for (size_t f = 0; f < nf && same_faces; ++f)
      for (int k = 0; k < 3; ++k)
        if (faces_[3 * f + k] != static_cast<unsigned>(F(f, k))) {
          same_faces = false;
          break;
        }
  }
  if (!same_faces) {
    faces_.resize(3 * nf);
    for (size_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int i = F(f, k);
        if (i < 0 || static_cast<size_t>(i) >= nv)
          throw std::invalid_argument("SetCloth: F(" + std::to_string(f) + "," +
                                      std::to_string(k) + ") = " + std::to_string(i) +
                                      " is not a vertex index in [0, " + std::to_string(nv) +
                                      ")");
        faces_[3 * f + k] = static_cast<unsigned>(i);
      }
  }
  positions_.resize(nv);
  uvs_.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    positions_[i] = Eigen::Vector3f(static_cast<float>(V(i, 0)), static_cast<float>(V(i, 1)),
                                    static_cast<float>(V(i, 2)) + lift_);
    uvs_[i] = Eigen::Vector2f(static_cast<float>(UV(i, 0)), static_cast<float>(UV(i, 1)));
  }
  // Smooth normals of the deformed mesh: area-weighted face normals (the cross product's
  // length is twice the area), so small slivers from remeshing do not tilt them.
  normals_.assign(nv, Eigen::Vector3f::Zero());
  for (size_t f = 0; f < nf; ++f) {
    const unsigned a = faces_[3 * f], b = faces_[3 * f + 1], c = faces_[3 * f + 2];
    const Eigen::Vector3f n = (positions_[b] - positions_[a]).cross(positions_[c] - positions_[a]);
    normals_[a] += n;
    normals_[b] += n;
    normals_[c] += n;
  }
  cloth_bounds_.setEmpty();
  for (const auto& q : positions_) cloth_bounds_.extend(q);
  for (auto& n : normals_) {
    const float len = n.norm();
    n = len > 1e-20f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitX();
  }

  if (!same_faces) {
    if (cloth_) {
      rtcDetachGeometry(cloth_scene_, cloth_id_);
      rtcReleaseGeometry(cloth_);
    }
    cloth_ = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(cloth_, RTC_BUILD_QUALITY_REFIT);
    rtcSetNewGeometryBuffer(cloth_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                            3 * sizeof(float), nv);
    unsigned* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        cloth_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nf));
    std::copy(faces_.begin(), faces_.end(), ib);
  }
  float* vb = static_cast<float*>(rtcGetGeometryBufferData(cloth_, RTC_BUFFER_TYPE_VERTEX, 0));
  for (size_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = positions_[i][k];
  if (same_faces) rtcUpdateGeometryBuffer(cloth_, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(cloth_);
  if (!same_faces) cloth_id_ = rtcAttachGeometry(cloth_scene_, cloth_);
  rtcCommitScene(cloth_scene_);
  CheckDevice(device_, "updating the cloth");
}

bool EmbreeScene::Intersect(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                            Hit* hit) const {
  const bool s = RawIntersect(scene_, org, dir, t_max, hit);
  Hit cloth_hit;
  if (cloth_ && RawIntersect(cloth_scene_, org, dir, s ? hit->t : t_max, &cloth_hit)) {
    *hit = cloth_hit;
    return true;
  }
  return s;
}

bool EmbreeScene::IntersectStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                  float t_max, Hit* hit) const {
  return RawIntersect(scene_, org, dir, t_max, hit);
}

bool EmbreeScene::IntersectCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                 float t_max, Hit* hit) const {
  return cloth_ && RawIntersect(cloth_scene_, org, dir, t_max, hit);
}

bool EmbreeScene::Occluded(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                           float t_max) const {
  return RawOccluded(scene_, org, dir, t_max) ||
         (cloth_ && RawOccluded(cloth_scene_, org, dir, t_max));
}

bool EmbreeScene::OccludedStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                 float t_max) const {
  return RawOccluded(scene_, org, dir, t_max);
}

bool EmbreeScene::OccludedCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                float t_max) const {
  return cloth_ && RawOccluded(cloth_scene_, org, dir, t_max);
}

bool EmbreeScene::RawIntersect(RTCScene scene, const Eigen::Vector3f& org,
                               const Eigen::Vector3f& dir, float t_max, Hit* hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = org.x(); rh.ray.org_y = org.y(); rh.ray.org_z = org.z();
  rh.ray.dir_x = dir.x(); rh.ray.dir_y = dir.y(); rh.ray.dir_z = dir.z();
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = t_max;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    hit->surface = Surface::kNone;
    return false;
  }
  hit->t = rh.ray.tfar;
  hit->point = org + rh.ray.tfar * dir;
  Eigen::Vector3f ng(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  ng.normalize();
  if (ng.dot(dir) > 0.0f) ng = -ng;
  hit->geom_normal = ng;
  hit->back_face = false;
  const unsigned gid = rh.hit.geomID;
  if (scene == cloth_scene_) {
    hit->surface = Surface::kCloth;
    const unsigned* f = &faces_[3 * rh.hit.primID];
    const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    Eigen::Vector3f n = w * normals_[f[0]] + u * normals_[f[1]] + v * normals_[f[2]];
    hit->uv = w * uvs_[f[0]] + u * uvs_[f[1]] + v * uvs_[f[2]];
    // Two-sided: the side facing the viewer is lit; interpolated normals of a strongly curved
    // cloth may still point away at grazing angles, so they are bent back to the visible side.
    if (n.dot(dir) > 0.0f) {
      n = -n;
      hit->back_face = true;
    }
    const float nn = n.norm();
    n = nn > 1e-12f ? Eigen::Vector3f(n / nn) : ng;
    if (n.dot(ng) < 0.05f) n = (n + (0.05f - n.dot(ng)) * ng).normalized();
    hit->normal = n;
  } else if (gid == ground_id_) {
    hit->surface = Surface::kGround;
    hit->normal = Eigen::Vector3f::UnitZ();
    hit->geom_normal = Eigen::Vector3f::UnitZ();
  } else if (gid == sphere_id_) {
    hit->surface = Surface::kFinial;
    hit->normal = ng;
  } else {
    hit->surface = Surface::kPole;
    hit->normal = ng;
    for (const Cylinder& c : cylinders_)
      if (c.geom_id == gid) {
        // The true cylinder normal (radial), not the facet's: the pole looks round.
        const Eigen::Vector3f d = hit->point - c.a;
        Eigen::Vector3f radial = d - d.dot(c.axis) * c.axis;
        if (radial.norm() > 1e-9f) hit->normal = radial.normalized();
        if (hit->normal.dot(dir) > 0.0f) hit->normal = -hit->normal;
        break;
      }
  }
  return true;
}

bool EmbreeScene::RawOccluded(RTCScene scene, const Eigen::Vector3f& org,
                              const Eigen::Vector3f& dir, float t_max) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  ray.org_x = org.x(); ray.org_y = org.y(); ray.org_z = org.z();
  ray.dir_x = dir.x(); ray.dir_y = dir.y(); ray.dir_z = dir.z();
  ray.tnear = 0.0f;
  ray.tfar = t_max;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(scene, &ctx, &ray);
  return ray.tfar < 0.0f;
}

}  // namespace clothwind::render
