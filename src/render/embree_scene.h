#ifndef CLOTHWIND_RENDER_EMBREE_SCENE_H_
#define CLOTHWIND_RENDER_EMBREE_SCENE_H_

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "render/render_params.h"

namespace clothwind::render {

// What a ray hit.
enum class Surface { kNone, kCloth, kPole, kFinial, kGround };

struct Hit {
  Surface surface = Surface::kNone;
  float t = 0.0f;                 // [m] along the (unit) ray
  Eigen::Vector3f point;          // [m] world
  Eigen::Vector3f normal;         // unit shading normal, facing the ray's origin side
  Eigen::Vector3f geom_normal;    // unit geometric normal, facing the ray's origin side
  Eigen::Vector2f uv;             // cloth texture coordinates (cloth only)
  bool back_face = false;         // cloth: the ray hit the side opposite the vertex normals
};

// The Embree scene of one clip: the cloth (updated every frame), a pole with a ball on top
// (flag) or a rod on two posts (cloth), and the ground plane z = 0: two Embree triangles over
// ±kGroundHalfSize, and past their edges the plane itself, so that a far camera sees ground up
// to the horizon (the triangles stay so that the pixels the datasets were made with stay).
//
// The cloth comes as plain arrays in the simulator's frame (z up, hoist on the z axis, wind
// along +x); the scene lifts it by p.mesh_height. Its BVH is refitted each frame when the
// faces stay the same (the common case); new faces (remeshing) rebuild it.
class EmbreeScene {
 public:
  static constexpr float kGroundHalfSize = 500.0f;  // [m] of the ground's two triangles
  // Vertex coordinates of the cloth are refused beyond this [m]: the scene is at most ~1e4 m
  // across, and past it the cross products of the normals overflow float.
  static constexpr double kMaxClothCoordinate = 1e6;

  // Inputs: p  render parameters (scene kind, mesh size and height);
  //   device_config  Embree's device configuration (tests pass a bad one to see its error).
  // Throws std::runtime_error naming Embree's error if the device or scene cannot be made.
  explicit EmbreeScene(const RenderParams& p, const std::string& device_config = "threads=1");
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Sets the cloth for the next frames.
  // Inputs:
  //   V   #V by 3 vertex positions [m], simulator frame
  //   F   #F by 3 vertex indices (counter-clockwise seen from the front of the texture)
  //   UV  #V by 2 texture coordinates in [0,1] (u from hoist to fly, v from bottom to top)
  // Throws std::invalid_argument on mismatched sizes, out-of-range indices, or a vertex or
  // texture coordinate that is not finite (as float) or beyond kMaxClothCoordinate, naming the
  // row and column; then the scene is unchanged (the previous cloth still renders). Throws
  // std::runtime_error on an Embree error; then the scene has no cloth.
  void SetCloth(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& UV);

  // Intersects a ray with everything. Inputs: org [m], dir (unit), t_max [m]. Outputs: hit.
  // Returns true if anything was hit before t_max.
  bool Intersect(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                 Hit* hit) const;
  // The same against the static part only (pole, ground) or the cloth only. The renderer
  // caches what camera rays see of the static part, since the camera does not move in a clip.
  bool IntersectStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                       Hit* hit) const;
  bool IntersectCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                      Hit* hit) const;

  // True if anything (resp. the static part, the cloth) blocks the segment org + t dir,
  // t in (0, t_max).
  bool Occluded(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max) const;
  bool OccludedStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max) const;
  bool OccludedCloth(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max) const;

  // Axis-aligned bounds of the current cloth (world) [m]; empty before SetCloth.
  const Eigen::AlignedBox3f& cloth_bounds() const { return cloth_bounds_; }

  // Per-vertex unit normals of the current cloth (#V by 3, world frame): area-weighted face
  // normals, recomputed on every SetCloth.
  const std::vector<Eigen::Vector3f>& cloth_normals() const { return normals_; }

 private:
  // Embree handles that release themselves: a constructor throwing half way leaked the device
  // and scenes made before the throw.
  struct DeviceRelease {
    void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
  };
  struct SceneRelease {
    void operator()(RTCScene s) const { rtcReleaseScene(s); }
  };
  struct GeometryRelease {
    void operator()(RTCGeometry g) const { rtcReleaseGeometry(g); }
  };
  using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceRelease>;
  using SceneHandle = std::unique_ptr<RTCSceneTy, SceneRelease>;
  using GeometryHandle = std::unique_ptr<RTCGeometryTy, GeometryRelease>;

  // The cloth's arrays as SetCloth derives them from its input (validated, world frame).
  struct ClothArrays {
    std::vector<Eigen::Vector3f> positions, normals;
    std::vector<Eigen::Vector2f> uvs;
    std::vector<unsigned> faces;  // 3 per face
    Eigen::AlignedBox3f bounds;
  };
  ClothArrays MakeClothArrays(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                              const Eigen::MatrixXd& UV) const;
  // A new cloth geometry holding `c` (not attached); throws on an Embree error.
  GeometryHandle NewClothGeometry(const ClothArrays& c) const;
  // Hands `c` to Embree: refits the attached geometry (same faces) or replaces it.
  void UploadCloth(const ClothArrays& c, bool same_faces);
  void DropCloth();

  struct Cylinder {
    unsigned geom_id;
    Eigen::Vector3f a, axis;  // start point, unit axis
  };
  SceneHandle NewScene(RTCBuildQuality quality) const;
  GeometryHandle NewGeometry(RTCGeometryType type, const char* what) const;
  void AddCylinder(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float radius);
  void AddGround();
  void AddSphere(const Eigen::Vector3f& c, float radius);

  // Declared in release order's reverse: the device outlives its scenes and geometries.
  DeviceHandle device_;
  SceneHandle scene_;        // static: pole, finial, ground
  SceneHandle cloth_scene_;  // the cloth alone, refitted every frame
  GeometryHandle cloth_;     // attached to cloth_scene_ as cloth_id_
  Eigen::AlignedBox3f cloth_bounds_;
  unsigned cloth_id_ = RTC_INVALID_GEOMETRY_ID;
  unsigned ground_id_ = RTC_INVALID_GEOMETRY_ID;
  unsigned sphere_id_ = RTC_INVALID_GEOMETRY_ID;
  std::vector<Cylinder> cylinders_;
  float lift_ = 0.0f;  // mesh_height [m]
  std::vector<Eigen::Vector3f> positions_;  // world, current frame
  std::vector<Eigen::Vector3f> normals_;
  std::vector<Eigen::Vector2f> uvs_;
  std::vector<unsigned> faces_;  // 3 per face

  bool RawIntersect(RTCScene scene, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                    float t_max, Hit* hit) const;
  bool RawOccluded(RTCScene scene, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                   float t_max) const;
  // Where the ray meets the plane z = 0 outside the ground's triangles, before t_max.
  // Outputs: t [m] along the ray. Returns false if it does not.
  static bool GroundPastTriangles(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                                  float t_max, float* t);
  bool IntersectStaticOrGround(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                               float t_max, Hit* hit) const;
};

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_EMBREE_SCENE_H_
