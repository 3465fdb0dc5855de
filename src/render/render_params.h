#ifndef CLOTHWIND_RENDER_RENDER_PARAMS_H_
#define CLOTHWIND_RENDER_RENDER_PARAMS_H_

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace clothwind::render {

// Which of the seed's two datasets a clip belongs to: FlagSim (3:2 flag on a pole) or
// ClothSim (1:1 cloth hanging from a rod).
enum class SceneKind { kFlag, kCloth };

std::string SceneKindName(SceneKind kind);                // "flag" | "cloth"
SceneKind SceneKindFromName(const std::string& name);     // throws on anything else

// The render parameters ζ of one clip (seed Table 2), plus the few choices Table 2 leaves
// open (sun azimuth, sky strength, field of view, texture colours), so that a clip is
// reproducible from label.json alone. Lengths in metres, angles in degrees.
struct RenderParams {
  SceneKind scene = SceneKind::kFlag;
  uint64_t seed = 0;  // pixel-sampling seed (anti-aliasing and shadow sample positions)

  // Background (Table 2: background_image, background_offset, background_scale). An empty
  // background_image means a procedural outdoor backdrop drawn from background_seed.
  std::string background_image;
  uint64_t background_seed = 0;
  double background_offset = 0.0;  // [m] lateral shift of the backdrop, ~U(-20, 20)
  double background_scale = 1.0;   // backdrop size factor, ~U(0.6, 1.0)

  // Sun (Table 2). The sun is a distant disc light whose direction points from the mesh's foot
  // (the ground point below the mesh's centre) to (sun_radius, sun_azimuth, sun_height).
  double sun_height = 7.0;        // [m] ~U(4, 10)
  double sun_radius = 2.5;        // [m] ~U(0, 5)
  double sun_azimuth_deg = 0.0;   // [deg] from +x (downwind) counter-clockwise; ~U(-180, 180)
  double sun_strength = 5.0;      // irradiance [W/m^2 in Blender's units], ~U(2, 10)
  double sun_shadow_soft_size = 5.0;  // [deg] angular diameter of the sun disc, ~U(2, 10)
  double sky_strength = 1.0;      // ambient sky irradiance factor, ~U(0.7, 1.3)

  int samples = 4;  // anti-aliasing samples per pixel (each with one shadow ray)

  // Camera (Table 2): on a circle of radius camera_radius about the mesh's centre, at
  // camera_height above ground, camera_angle degrees off the side-on view, looking at the
  // mesh's centre.
  double camera_height = 1.6;     // [m] flag ~U(0.2, 3), cloth ~U(0.5, 2)
  double camera_radius = 5.0;     // [m] horizontal distance, flag ~U(4, 6), cloth ~U(1, 2.5)
  double camera_angle_deg = 0.0;  // [deg] flag ~U(-15, 15), cloth ~U(-5, 5)
  double camera_fov_deg = 45.0;   // [deg] horizontal = vertical field of view (square frame)
  // Where the camera looks [m, world]; unset: the mesh's rest centre (see MeshCentre). Set by
  // FrameClip from a clip's frames, so a hanging flag (low wind) is framed as well as a flying
  // one, as the seed's real clips were cropped around the flag. JSON: [x, y, z] or absent.
  bool has_look_at = false;
  double look_at[3] = {0.0, 0.0, 0.0};

  // Mesh (Table 2): the simulator's frame is lifted by mesh_height (its origin, the hoist's
  // lower corner for flags, goes to that height above the ground).
  double mesh_height = 4.6;       // [m] flag 4.6, cloth 2
  double mesh_width = 3.0;        // [m] length of the flag / width of the cloth at rest
  double mesh_aspect_ratio = 1.5; // width : height, flag 3:2, cloth 1:1

  // Texture (Table 2 mesh_texture): kind "flag" with a FlagDesign name, or kind "fabric" with a
  // FabricPattern name; texture_seed picks its colours.
  std::string texture_kind = "flag";
  std::string texture_name = "vertical_tricolour";
  uint64_t texture_seed = 0;

  // Frame format of the seed's data: 300x300 RGB at 25 fps.
  int width = 300;
  int height = 300;
  double fps = 25.0;

  // Mesh height at rest [m] (mesh_width / mesh_aspect_ratio).
  double MeshRestHeight() const { return mesh_width / mesh_aspect_ratio; }
};

// Where a dataset's cameras stand: ζ's camera_height ~ U(height_min, height_max),
// camera_radius ~ U(radius_min, radius_max), camera_angle_deg ~ U(-angle_max_deg, angle_max_deg).
// Table 2's ranges by default; narrower or other ranges let a dataset match one site's camera
// (docs/datasets.md, "Cameras"). Lengths in metres, angles in degrees.
struct CameraRanges {
  double height_min = 0.2, height_max = 3.0;  // [m] above the ground
  double radius_min = 4.0, radius_max = 6.0;  // [m] horizontal distance to the mesh's centre
  double angle_max_deg = 15.0;                // [deg] off the side-on view, either way
  bool operator==(const CameraRanges& o) const;
  bool operator!=(const CameraRanges& o) const { return !(*this == o); }
};

// Table 2's camera ranges: flag height 0.2-3, radius 4-6, angle ±15; cloth 0.5-2, 1-2.5, ±5.
CameraRanges TableTwoCameraRanges(SceneKind kind);

// The nearest a camera may stand to its target horizontally [m] (ζ.camera_radius and
// CameraRanges::radius_min): nearer, it looks (almost) straight up or down.
constexpr double kMinCameraRadius = 0.1;

// Throws std::invalid_argument naming the field ("camera height", ...) unless
// 0 < min <= max <= 100 m for height, 0.1 <= min <= max <= 1000 m for radius and
// 0 <= angle_max_deg < 90.
void ValidateCameraRanges(const CameraRanges& r);

// Draws ζ from the ranges of seed Table 2 for the given scene kind, the camera from `camera`
// (default: TableTwoCameraRanges(kind)). The camera's draws take the same places in the random
// stream whatever its ranges, so two datasets of one seed differ only in their cameras.
// Inputs: kind; seed  everything drawn follows from it; background_images  candidate files
//   (one is picked by seed); empty means procedural backdrops; camera  validated ranges.
RenderParams SampleRenderParams(SceneKind kind, uint64_t seed,
                                const std::vector<std::string>& background_images = {});
RenderParams SampleRenderParams(SceneKind kind, uint64_t seed,
                                const std::vector<std::string>& background_images,
                                const CameraRanges& camera);

// JSON round trip (for label.json). FromJson requires every field and names the one that is
// missing or of the wrong type (std::invalid_argument).
nlohmann::json ToJson(const RenderParams& p);
RenderParams RenderParamsFromJson(const nlohmann::json& j);

// Aims the camera of a clip at the centre of the cloth's bounding box over all its frames
// (sets p->look_at), instead of the flag's flying rest centre, and widens camera_fov_deg so that
// box fits in the frame with a 5 % margin: to at most kFrameClipMaxFovDeg, and never narrows it
// (a field of view already wider stays).
// Inputs: frames  each #V by 3 vertex positions [m] in the simulator's frame (as given to the
//   renderer; p->mesh_height lifts them). Throws std::invalid_argument if there are none or a
//   coordinate is not finite (naming the frame and vertex).
constexpr double kFrameClipMaxFovDeg = 120.0;
void FrameClip(const std::vector<Eigen::MatrixXd>& frames, RenderParams* p);

// The size at rest of the cloth a renderer is given, measured from one of its frames: the
// area-weighted mean over the faces of how many metres one unit of u (and of v) spans. The
// texture map follows the material, so a folded or flying cloth measures its rest size to within
// its stretch (a few percent), and no rest state is needed.
// Inputs: V  #V by 3 positions [m]; F  #F by 3 faces; UV  #V by 2 texture coordinates spanning
//   [0,1] (u hoist to fly, v bottom to top), as the renderer takes them.
// Returns (width along u, height along v) [m]. Throws std::invalid_argument on mismatched
// sizes, bad indices, or texture coordinates that span no area.
Eigen::Vector2d MeasureClothSize(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                 const Eigen::MatrixXd& UV);

// Why ζ does not fit a cloth of the measured size: the pole, rod and camera aim follow
// ζ.mesh_width and ζ.mesh_aspect_ratio, so a cloth of another size flew off its pole unseen.
// Inputs: p; size  (width, height) [m], from MeasureClothSize; tolerance  relative, e.g. 0.05.
// Returns "" if the width and the rest height (width / aspect) are both within tolerance of
// ζ's, else a message naming 'mesh_width' or 'mesh_aspect_ratio' with both sizes.
std::string MeshSizeMismatch(const RenderParams& p, const Eigen::Vector2d& size,
                             double tolerance = 0.05);

// Sets ζ's mesh_width and mesh_aspect_ratio to a cloth of `size` (width, height) [m].
void SetMeshSize(const Eigen::Vector2d& size, RenderParams* p);

// Checks the values are usable (positive sizes, samples >= 1, known texture, a camera at least
// kMinCameraRadius from its target and at most 1000 m up, ...); throws std::invalid_argument
// naming the field and the expected range.
void ValidateRenderParams(const RenderParams& p);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_RENDER_PARAMS_H_
