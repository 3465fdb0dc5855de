#include "render/embree_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothwind::render {

namespace {
const char* ErrorName(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE: return "none";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
  }
  return "an unknown error code";
}

// Embree reports errors through a C callback (throwing across it is undefined), so errors are
// read back with rtcGetDeviceError after each call that can fail, before its result is used.
void CheckDevice(RTCDevice device, const std::string& what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error ") + ErrorName(e) + " (" +
                             std::to_string(e) + ") in " + what);
}

// A new buffer of `count` items of `stride` bytes attached to g, checked before it is written:
// a failed allocation returns null, and the writes went through it.
template <typename T>
T* NewBuffer(RTCDevice device, RTCGeometry g, RTCBufferType type, RTCFormat format,
             size_t stride, size_t count, const char* what) {
  void* b = rtcSetNewGeometryBuffer(g, type, 0, format, stride, count);
  CheckDevice(device, what);
  if (!b) throw std::runtime_error(std::string("Embree returned no buffer in ") + what);
  return static_cast<T*>(b);
}

constexpr float kPoleRadius = 0.035f;  // [m]
}  // namespace

EmbreeScene::EmbreeScene(const RenderParams& p, const std::string& device_config) {
  // One build thread: frames are rendered many at a time by the caller's threads, and a
  // 1000-vertex refit takes microseconds.
  device_.reset(rtcNewDevice(device_config.c_str()));
  if (!device_) {
    // Without a device the error is the thread's, read with a null device.
    const RTCError e = rtcGetDeviceError(nullptr);
    throw std::runtime_error("Embree: cannot create a device with configuration '" +
                             device_config + "': " + ErrorName(e) + " (" + std::to_string(e) +
                             ")");
  }
  scene_ = NewScene(RTC_BUILD_QUALITY_HIGH);
  cloth_scene_ = NewScene(RTC_BUILD_QUALITY_LOW);
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
  rtcCommitScene(scene_.get());
  CheckDevice(device_.get(), "building the static scene");
}

// The handles release the cloth, the scenes and then the device (members in reverse order).
EmbreeScene::~EmbreeScene() = default;

EmbreeScene::SceneHandle EmbreeScene::NewScene(RTCBuildQuality quality) const {
  SceneHandle scene(rtcNewScene(device_.get()));
  CheckDevice(device_.get(), "creating a scene");
  if (!scene) throw std::runtime_error("Embree returned no scene");
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(scene.get(), quality);
  CheckDevice(device_.get(), "setting up a scene");
  return scene;
}

EmbreeScene::GeometryHandle EmbreeScene::NewGeometry(RTCGeometryType type,
                                                     const char* what) const {
  GeometryHandle g(rtcNewGeometry(device_.get(), type));
  CheckDevice(device_.get(), std::string("creating ") + what);
  if (!g) throw std::runtime_error(std::string("Embree returned no geometry for ") + what);
  return g;
}

void EmbreeScene::AddCylinder(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float radius) {
  constexpr int kSegments = 16;
  const Eigen::Vector3f axis = (b - a).normalized();
  const Eigen::Vector3f helper =
      std::abs(axis.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f e1 = axis.cross(helper).normalized(), e2 = axis.cross(e1);
  GeometryHandle g = NewGeometry(RTC_GEOMETRY_TYPE_TRIANGLE, "the pole");
  float* vb = NewBuffer<float>(device_.get(), g.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3,
                               3 * sizeof(float), 2 * kSegments, "the pole's vertices");
  unsigned* ib = NewBuffer<unsigned>(device_.get(), g.get(), RTC_BUFFER_TYPE_INDEX,
                                     RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2 * kSegments,
                                     "the pole's faces");
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
  rtcCommitGeometry(g.get());
  const unsigned id = rtcAttachGeometry(scene_.get(), g.get());
  CheckDevice(device_.get(), "adding the pole");
  cylinders_.push_back({id, a, axis});
}

void EmbreeScene::AddSphere(const Eigen::Vector3f& c, float radius) {
  GeometryHandle g = NewGeometry(RTC_GEOMETRY_TYPE_SPHERE_POINT, "the finial");
  float* vb = NewBuffer<float>(device_.get(), g.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT4,
                               4 * sizeof(float), 1, "the finial");
  vb[0] = c.x(); vb[1] = c.y(); vb[2] = c.z(); vb[3] = radius;
  rtcCommitGeometry(g.get());
  sphere_id_ = rtcAttachGeometry(scene_.get(), g.get());
  CheckDevice(device_.get(), "adding the finial");
}

void EmbreeScene::AddGround() {
  GeometryHandle g = NewGeometry(RTC_GEOMETRY_TYPE_TRIANGLE, "the ground");
  float* vb = NewBuffer<float>(device_.get(), g.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3,
                               3 * sizeof(float), 4, "the ground's vertices");
  unsigned* ib = NewBuffer<unsigned>(device_.get(), g.get(), RTC_BUFFER_TYPE_INDEX,
                                     RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2,
                                     "the ground's faces");
  const float s = kGroundHalfSize;
  const float corners[4][2] = {{-s, -s}, {s, -s}, {s, s}, {-s, s}};
  for (int i = 0; i < 4; ++i) {
    vb[3 * i] = corners[i][0];
    vb[3 * i + 1] = corners[i][1];
    vb[3 * i + 2] = 0.0f;
  }
  ib[0] = 0; ib[1] = 1; ib[2] = 2; ib[3] = 0; ib[4] = 2; ib[5] = 3;
  rtcCommitGeometry(g.get());
  ground_id_ = rtcAttachGeometry(scene_.get(), g.get());
  CheckDevice(device_.get(), "adding the ground");
}

namespace {
void CheckClothShapes(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
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
}

// Refuses a value that is not finite once a float (1e39 is finite as double, inf as float), or
// beyond `limit`, naming the vertex and the coordinate (names[col]: "xyz" or "uv").
float CheckedFloat(double value, double limit, const char* matrix, const char* names, size_t row,
                   int col) {
  const float f = static_cast<float>(value);
  if (!(std::isfinite(f) && std::abs(value) <= limit)) {
    std::ostringstream m;
    m << "SetCloth: vertex " << row << " has " << matrix << " coordinate " << names[col] << " = "
      << value << ", expected a finite value (as a float)";
    if (limit < std::numeric_limits<double>::max()) m << " within +-" << limit << " m";
    throw std::invalid_argument(m.str());
  }
  return f;
}
}  // namespace

EmbreeScene::ClothArrays EmbreeScene::MakeClothArrays(const Eigen::MatrixXd& V,
                                                      const Eigen::MatrixXi& F,
                                                      const Eigen::MatrixXd& UV) const {
  CheckClothShapes(V, F, UV);
  const size_t nv = V.rows(), nf = F.rows();
  ClothArrays c;
  c.faces.resize(3 * nf);
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k);
      if (i < 0 || static_cast<size_t>(i) >= nv)
        throw std::invalid_argument("SetCloth: F(" + std::to_string(f) + "," +
                                    std::to_string(k) + ") = " + std::to_string(i) +
                                    " is not a vertex index in [0, " + std::to_string(nv) + ")");
      c.faces[3 * f + k] = static_cast<unsigned>(i);
    }
  c.positions.resize(nv);
  c.uvs.resize(nv);
  constexpr double kNoUvLimit = std::numeric_limits<double>::max();
  for (size_t i = 0; i < nv; ++i) {
    float q[3], t[2];
    for (int k = 0; k < 3; ++k) q[k] = CheckedFloat(V(i, k), kMaxClothCoordinate, "V", "xyz", i, k);
    for (int k = 0; k < 2; ++k) t[k] = CheckedFloat(UV(i, k), kNoUvLimit, "UV", "uv", i, k);
    c.positions[i] = Eigen::Vector3f(q[0], q[1], q[2] + lift_);
    c.uvs[i] = Eigen::Vector2f(t[0], t[1]);
  }
  // Smooth normals of the deformed mesh: area-weighted face normals (the cross product's
  // length is twice the area), so small slivers from remeshing do not tilt them.
  c.normals.assign(nv, Eigen::Vector3f::Zero());
  for (size_t f = 0; f < nf; ++f) {
    const unsigned a = c.faces[3 * f], b = c.faces[3 * f + 1], d = c.faces[3 * f + 2];
    const Eigen::Vector3f n =
        (c.positions[b] - c.positions[a]).cross(c.positions[d] - c.positions[a]);
    c.normals[a] += n;
    c.normals[b] += n;
    c.normals[d] += n;
  }
  c.bounds.setEmpty();
  for (const auto& q : c.positions) c.bounds.extend(q);
  for (auto& n : c.normals) {
    const float len = n.norm();
    n = len > 1e-20f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitX();
  }
  return c;
}

EmbreeScene::GeometryHandle EmbreeScene::NewClothGeometry(const ClothArrays& c) const {
  RTCDevice d = device_.get();
  GeometryHandle g = NewGeometry(RTC_GEOMETRY_TYPE_TRIANGLE, "the cloth");
  rtcSetGeometryBuildQuality(g.get(), RTC_BUILD_QUALITY_REFIT);
  NewBuffer<float>(d, g.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                   c.positions.size(), "the cloth's vertices");
  unsigned* ib = NewBuffer<unsigned>(d, g.get(), RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3,
                                     3 * sizeof(unsigned), c.faces.size() / 3,
                                     "the cloth's faces");
  std::copy(c.faces.begin(), c.faces.end(), ib);
  return g;
}

void EmbreeScene::UploadCloth(const ClothArrays& c, bool same_faces) {
  RTCDevice d = device_.get();
  GeometryHandle fresh;
  if (!same_faces) fresh = NewClothGeometry(c);  // (SetCloth drops the old cloth if this throws)
  RTCGeometry g = same_faces ? cloth_.get() : fresh.get();
  float* vb = static_cast<float*>(rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_VERTEX, 0));
  CheckDevice(d, "reading the cloth's vertex buffer");
  if (!vb) throw std::runtime_error("Embree returned no vertex buffer for the cloth");
  for (size_t i = 0; i < c.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = c.positions[i][k];
  if (same_faces) rtcUpdateGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(g);
  CheckDevice(d, "committing the cloth");
  if (!same_faces) {
    if (cloth_) rtcDetachGeometry(cloth_scene_.get(), cloth_id_);
    cloth_ = std::move(fresh);
    cloth_id_ = rtcAttachGeometry(cloth_scene_.get(), cloth_.get());
  }
  rtcCommitScene(cloth_scene_.get());
  CheckDevice(d, "updating the cloth");
}

void EmbreeScene::DropCloth() {
  if (cloth_ && cloth_id_ != RTC_INVALID_GEOMETRY_ID) {  // a failed attach left no id to detach
    rtcDetachGeometry(cloth_scene_.get(), cloth_id_);
    rtcCommitScene(cloth_scene_.get());
  }
  // The failed upload's error, and any of this cleanup, is read and so cleared: left pending, it
  // made the next, valid SetCloth throw.
  rtcGetDeviceError(device_.get());
  cloth_.reset();
  cloth_id_ = RTC_INVALID_GEOMETRY_ID;
  positions_.clear();
  normals_.clear();
  uvs_.clear();
  faces_.clear();
  cloth_bounds_.setEmpty();
}

void EmbreeScene::SetCloth(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                           const Eigen::MatrixXd& UV) {
  // Everything is checked and derived before anything changes: a bad index half way through
  // left the faces half new while Embree held the old geometry (reads out of bounds later).
  ClothArrays c = MakeClothArrays(V, F, UV);
  const bool same_faces = cloth_ && c.faces == faces_ && c.positions.size() == positions_.size();
  try {
    UploadCloth(c, same_faces);
  } catch (...) {
    // Embree may hold part of the new cloth: no cloth rather than arrays that disagree with it.
    DropCloth();
    throw;
  }
  positions_.swap(c.positions);
  normals_.swap(c.normals);
  uvs_.swap(c.uvs);
  faces_.swap(c.faces);
  cloth_bounds_ = c.bounds;
}

bool EmbreeScene::GroundPastTriangles(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                      float t_max, float* t) {
  if (!(org.z() > 0.0f && dir.z() < 0.0f)) return false;
  const float tt = -org.z() / dir.z();
  if (!(tt < t_max)) return false;
  const float x = org.x() + tt * dir.x(), y = org.y() + tt * dir.y();
  // Inside the triangles' square Embree's answer stands, hit or miss, as it always did; the plane
  // takes over a millimetre inside their edge, where Embree's own test may miss by a hair (sky
  // specks along the edge for a far camera). Rays of the datasets' cameras never come near it.
  constexpr float kEdge = kGroundHalfSize - 1e-3f;
  if (std::abs(x) <= kEdge && std::abs(y) <= kEdge) return false;
  *t = tt;
  return true;
}

bool EmbreeScene::IntersectStaticOrGround(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                          float t_max, Hit* hit) const {
  if (RawIntersect(scene_.get(), org, dir, t_max, hit)) return true;
  float t;
  if (!GroundPastTriangles(org, dir, t_max, &t)) return false;
  hit->surface = Surface::kGround;
  hit->t = t;
  hit->point = org + t * dir;
  hit->point.z() = 0.0f;
  hit->normal = Eigen::Vector3f::UnitZ();
  hit->geom_normal = Eigen::Vector3f::UnitZ();
  hit->back_face = false;
  return true;
}

bool EmbreeScene::Intersect(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                            Hit* hit) const {
  const bool s = IntersectStaticOrGround(org, dir, t_max, hit);
  Hit cloth_hit;
  if (cloth_ && RawIntersect(cloth_scene_.get(), org, dir, s ? hit->t : t_max, &cloth_hit)) {
    *hit = cloth_hit;
    return true;
  }
  return s;
}

bool EmbreeScene::IntersectStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                  float t_max, Hit* hit) const {
  return IntersectStaticOrGround(org, dir, t_max, hit);
}

bool EmbreeScene::IntersectCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                 float t_max, Hit* hit) const {
  return cloth_ && RawIntersect(cloth_scene_.get(), org, dir, t_max, hit);
}

bool EmbreeScene::Occluded(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                           float t_max) const {
  return OccludedStatic(org, dir, t_max) ||
         (cloth_ && RawOccluded(cloth_scene_.get(), org, dir, t_max));
}

bool EmbreeScene::OccludedStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                 float t_max) const {
  float t;
  return RawOccluded(scene_.get(), org, dir, t_max) || GroundPastTriangles(org, dir, t_max, &t);
}

bool EmbreeScene::OccludedCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                float t_max) const {
  return cloth_ && RawOccluded(cloth_scene_.get(), org, dir, t_max);
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
  if (scene == cloth_scene_.get()) {
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
