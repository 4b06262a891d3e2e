// one frame as a POV-Ray 3.7 scene (the renderer of Shao et al. 2017): the camera framing, the cloth
// as a mesh2 coloured by saturation, the water as a surface mesh or spheres, the colliders at their
// pose, a floor, lights. POV-Ray is left-handed; soak is right-handed with y up, so the camera's
// right vector is negated (POV-Ray's documented way to render right-handed data).
#pragma once
#include <optional>
#include <soak/math.hpp>
#include <soak/model.hpp>
#include <string>
#include <vector>

#include <soak/render.hpp>

#include "render/run_output.hpp"
#include "render/surface.hpp"
#include "world/colliders.hpp"

namespace soak {

struct Bounds {
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  bool empty() const { return lo.x() > hi.x(); }
  void add(const Vec3& p, float pad = 0.0f);
  void add(const Bounds& b);
};

// world bounds of a collider at a pose; empty for a plane (infinite)
Bounds colliderBounds(const Collider& c, const ColliderPose& pose);

// automatic framing: collects points (and boxes) and places the camera to look at the centre of their
// bounds (or the requested point) from the requested direction, at the smallest distance at which
// every point is inside the picture, plus a margin. Only the bounds and the largest projection of the
// points on four directions are kept, so any number of frames can be added.
class CameraFit {
 public:
  CameraFit(const CameraRequest& request, int width, int height);
  void add(const Vec3& p, float pad = 0.0f);
  void add(const Bounds& b);  // its eight corners
  const Bounds& bounds() const { return bounds_; }
  CameraSpec camera() const;

 private:
  CameraRequest request_;
  Vec3 toCamera_, right_, up_;
  float tanH_ = 1.0f, tanV_ = 1.0f;
  Bounds bounds_;
  // max over the points of p . (toCamera +- right / tanH) and p . (toCamera +- up / tanV)
  float support_[4] = {-1e30f, -1e30f, -1e30f, -1e30f};
  Vec3 direction_[4];
};

// the camera that shows every corner of `bounds` (CameraFit with the eight corners)
CameraSpec frameCamera(const Bounds& bounds, const CameraRequest& request, int width, int height);

struct PovFrameInput {
  const Model* model = nullptr;                  // colliders
  std::vector<ColliderPose> poses;               // one per collider, at the frame's time
  std::vector<const SurfaceMesh*> colliderMesh;  // per collider: a mesh's, a body's or a sequence's surface (may be empty)
  const ClothFrame* cloth = nullptr;
  std::vector<Vec3> clothColor;  // per cloth vertex (0..1); empty: the plain fabric colour
  WaterStyle water = WaterStyle::Particles;
  const SurfaceMesh* surface = nullptr;  // WaterStyle::Surface
  std::vector<Vec3> dropCentre;          // WaterStyle::Particles: sphere centres (m)
  std::vector<float> dropRadius;         // and radii (m)
  CameraSpec camera;
  int width = 640, height = 480;
  std::optional<float> floorY;  // draw a floor plane at this height (no plane collider)
  float checker = 0.1f;         // m, side of a floor square
  std::string title;            // a comment line
};

// the colours of the cloth's vertices: from its saturation with the ramp when the frame has one
// (rampColor, wetting.hpp: the paper's dry colour to black at S^MAX, display values given as `srgb`),
// else the OBJ's colours, else empty (plain fabric)
std::vector<Vec3> clothColors(const ClothFrame& cloth, const std::string& ramp, float saturationMax);

// the whole .pov text of one frame
std::string povScene(const PovFrameInput& in);

}  // namespace soak
