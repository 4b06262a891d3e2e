// one frame as a POV-Ray scene (render/pov.cpp): the automatic camera frames every point, the user's
// camera is kept, colliders are drawn at their pose, the cloth as a mesh2 with a texture or normal per
// vertex, the water as spheres or a surface, and the paper's saturation ramps. Text only: no POV-Ray
#include "render/pov.hpp"
#include "wetting/wetting.hpp"

#include <soak/scene.hpp>

#include <gtest/gtest.h>

#include "render/render_support.hpp"
#include "world/colliders.hpp"
#include "world/container.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace soak {
namespace {

using soak::testing::kTinyScene;

// how many times `needle` occurs in `text`
size_t count(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// the text between `open` and the next " }" after it
std::string section(const std::string& text, const std::string& open) {
  const size_t a = text.find(open);
  if (a == std::string::npos) return "";
  return text.substr(a, text.find(" }", a) - a);
}

// a unit square of two triangles and a fifth vertex in no triangle
ClothFrame square() {
  ClothFrame c;
  c.x = {Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(1, 1, -1), Vec3(0, 1, -1), Vec3(3, 3, 3)};
  c.triangles = {{0, 1, 2}, {0, 2, 3}};
  return c;
}

TEST(RenderCamera, AutomaticFramingShowsEveryCornerAndFillsThePicture) {
  Bounds b;
  b.add(Vec3(-1.2f, -0.5f, -0.3f));
  b.add(Vec3(0.8f, 1.6f, 0.4f));
  for (float az : {0.0f, 35.0f, 120.0f, -70.0f})
    for (float el : {10.0f, 25.0f, 60.0f})
      for (auto [w, h] : {std::pair{640, 480}, std::pair{300, 600}}) {
        CameraRequest req;
        req.azimuthDegrees = az;
        req.elevationDegrees = el;
        const CameraSpec cam = frameCamera(b, req, w, h);
        const Vec3 fwd = (cam.lookAt - cam.position).normalized();
        const Vec3 right = fwd.cross(Vec3(0, 1, 0)).normalized();
        const Vec3 up = right.cross(fwd);
        const float tanH = std::tan(0.5f * cam.fovDegrees * kPi / 180.0f), tanV = tanH * float(h) / float(w);
        float widest = 0.0f;
        for (int k = 0; k < 8; ++k) {
          const Vec3 p((k & 1) ? b.hi.x() : b.lo.x(), (k & 2) ? b.hi.y() : b.lo.y(), (k & 4) ? b.hi.z() : b.lo.z());
          const Vec3 d = p - cam.position;
          const float depth = d.dot(fwd);
          ASSERT_GT(depth, 0.0f);
          const float sx = d.dot(right) / depth / tanH, sy = d.dot(up) / depth / tanV;
          EXPECT_LE(std::abs(sx), 1.0f) << az << " " << el;
          EXPECT_LE(std::abs(sy), 1.0f) << az << " " << el;
          widest = std::max({widest, std::abs(sx), std::abs(sy)});
        }
        EXPECT_GT(widest, 0.85f) << "the bounds should fill the picture, az " << az << " el " << el;
      }
}

TEST(RenderCamera, EveryPointAddedIsInThePictureAndZoomMovesCloser) {
  // a cloud of points with radii (water particles), one stray drop far to the side
  CameraRequest req;
  CameraFit fit(req, 480, 360);
  std::vector<std::pair<Vec3, float>> pts;
  uint32_t seed = 12345;
  auto rnd = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1 << 24);
  };
  for (int i = 0; i < 500; ++i) pts.push_back({Vec3(rnd() - 0.5f, 2.0f * rnd(), rnd() - 0.5f), 0.02f});
  pts.push_back({Vec3(1.4f, 0.1f, -0.9f), 0.0125f});
  for (const auto& [p, r] : pts) fit.add(p, r);
  const CameraSpec cam = fit.camera();
  const Vec3 fwd = (cam.lookAt - cam.position).normalized();
  const Vec3 right = fwd.cross(Vec3(0, 1, 0)).normalized();
  const Vec3 up = right.cross(fwd);
  const float tanH = std::tan(0.5f * cam.fovDegrees * kPi / 180.0f), tanV = tanH * 360.0f / 480.0f;
  float widest = 0.0f;
  for (const auto& [p, r] : pts) {
    const Vec3 d = p - cam.position;
    const float depth = d.dot(fwd);
    // the ball's silhouette edge: centre offset plus its radius
    const float sx = (std::abs(d.dot(right)) + r) / depth / tanH, sy = (std::abs(d.dot(up)) + r) / depth / tanV;
    EXPECT_LE(sx, 1.0f);
    EXPECT_LE(sy, 1.0f);
    widest = std::max({widest, sx, sy});
  }
  EXPECT_GT(widest, 0.85f);
  req.zoom = 2.0f;
  CameraFit closer(req, 480, 360);
  for (const auto& [p, r] : pts) closer.add(p, r);
  const CameraSpec zoomed = closer.camera();
  EXPECT_NEAR((zoomed.position - zoomed.lookAt).norm(), 0.5f * (cam.position - cam.lookAt).norm(), 1e-4f);
  EXPECT_EQ(zoomed.lookAt, cam.lookAt);
}

TEST(RenderCamera, UserCameraIsKept) {
  Bounds b;
  b.add(Vec3(0, 0, 0), 1.0f);
  CameraRequest req;
  req.position = Vec3(3, 2, 1);
  req.lookAt = Vec3(0, 0.5f, 0);
  req.fovDegrees = 30.0f;
  const CameraSpec cam = frameCamera(b, req, 100, 100);
  EXPECT_EQ(cam.position, Vec3(3, 2, 1));
  EXPECT_EQ(cam.lookAt, Vec3(0, 0.5f, 0));
  EXPECT_EQ(cam.fovDegrees, 30.0f);
}

TEST(RenderScene, CollidersAreDrawnAtTheirKeyframedPose) {
  const Scene scene = loadSceneFromString(kTinyScene, "tiny.json", ".");
  const Collider& crate = scene.model.colliders[2];
  // at the first key: a 0.1 m cube at (-0.2, 0.05, 0); at the last: raised to 0.25 and turned 45 degrees
  const Bounds start = colliderBounds(crate, colliderPose(crate, 0.0));
  EXPECT_NEAR(start.lo.y(), 0.0f, 1e-5f);
  EXPECT_NEAR(start.hi.x() - start.lo.x(), 0.1f, 1e-5f);
  const Bounds end = colliderBounds(crate, colliderPose(crate, 0.06));
  EXPECT_NEAR(end.lo.y(), 0.2f, 1e-5f);
  EXPECT_NEAR(end.hi.x() - end.lo.x(), 0.1f * std::sqrt(2.0f), 1e-4f);
  EXPECT_TRUE(colliderBounds(scene.model.colliders[0], colliderPose(scene.model.colliders[0], 0.0)).empty());

  PovFrameInput in;
  in.model = &scene.model;
  for (const Collider& c : scene.model.colliders) in.poses.push_back(colliderPose(c, 0.06));
  const std::string pov = povScene(in);
  EXPECT_NE(pov.find("plane { <0,1,0>, 0 texture { Floor } }"), std::string::npos);
  EXPECT_NE(pov.find("sphere { <0,0,0>, 0.05"), std::string::npos);
  EXPECT_NE(pov.find(", -0.2,0.25,0>"), std::string::npos) << pov;  // the crate's matrix ends with its position
  EXPECT_NE(pov.find("right -x*"), std::string::npos);              // right-handed data in POV-Ray
}

TEST(RenderScene, SaturationRampsOfThePaper) {
  EXPECT_EQ(rampColor("red", 0.0f, 0.4f), Vec3(1, 0, 0));
  EXPECT_EQ(rampColor("green", 0.0f, 0.4f), Vec3(0, 1, 0));
  EXPECT_EQ(rampColor("red", 0.4f, 0.4f), Vec3(0, 0, 0));
  EXPECT_EQ(rampColor("red", 0.9f, 0.4f), Vec3(0, 0, 0));
  EXPECT_NEAR(rampColor("green", 0.1f, 0.4f).y(), 0.75f, 1e-6f);
  ClothFrame plain;
  plain.x.assign(3, Vec3::Zero());
  EXPECT_TRUE(clothColors(plain, "red", 0.4f).empty());  // no saturation: the plain fabric colour
}

// the cloth is one mesh2: a vertex and a normal per vertex, a texture per vertex when it has colours
// (srgb, to 4 decimals) with each face naming its corners' textures; without colours one plain fabric
TEST(RenderPov, ClothIsAMesh2WithATextureAndANormalPerVertex) {
  ClothFrame c = square();
  c.normal.assign(5, Vec3(0, 1, 0));
  PovFrameInput in;
  in.cloth = &c;
  in.clothColor = {Vec3(1, 0, 0), Vec3(0.5f, 0, 0), Vec3(0.25f, 0, 0), Vec3(0, 0, 0), Vec3(0.125f, 0, 0)};
  const std::string pov = povScene(in);
  EXPECT_EQ(count(pov, "mesh2 {"), 1u);
  EXPECT_NE(pov.find("vertex_vectors { 5,\n<0,1,0>,\n<1,1,0>,\n<1,1,-1>,\n<0,1,-1>,\n<3,3,3> }"), std::string::npos) << pov;
  EXPECT_NE(pov.find("normal_vectors { 5,"), std::string::npos);
  EXPECT_NE(pov.find("texture_list { 5,"), std::string::npos);
  EXPECT_NE(pov.find("pigment { srgb <0.5000,0.0000,0.0000> }"), std::string::npos);
  EXPECT_NE(pov.find("pigment { srgb <0.1250,0.0000,0.0000> }"), std::string::npos);
  EXPECT_NE(pov.find("face_indices { 2,\n<0,1,2>,0,1,2,\n<0,2,3>,0,2,3 }"), std::string::npos) << pov;
  EXPECT_EQ(pov.find("srgb <0.8000,0.7400,0.6200>"), std::string::npos);  // no plain fabric
  in.clothColor.clear();
  const std::string plain = povScene(in);
  EXPECT_EQ(plain.find("texture_list"), std::string::npos);
  EXPECT_NE(plain.find("face_indices { 2,\n<0,1,2>,\n<0,2,3> }"), std::string::npos) << plain;
  EXPECT_NE(plain.find("texture { pigment { srgb <0.8000,0.7400,0.6200> } finish { ClothFinish } }"), std::string::npos);
  // colours for the wrong number of vertices are not used
  in.clothColor.assign(3, Vec3(1, 0, 0));
  EXPECT_EQ(povScene(in).find("texture_list"), std::string::npos);
  // a cloth without triangles is not drawn
  ClothFrame empty;
  empty.x = c.x;
  in.cloth = &empty;
  EXPECT_EQ(povScene(in).find("mesh2"), std::string::npos);
}

// a vertex without a usable normal (missing or zero) takes the normal of its triangles, one in no
// triangle takes +y: POV-Ray never gets a zero normal
TEST(RenderPov, MissingNormalsComeFromTheTriangles) {
  ClothFrame c = square();  // no normals
  PovFrameInput in;
  in.cloth = &c;
  const std::string normals = section(povScene(in), "normal_vectors");
  // (1,0,0) x (1,0,-1) = (0,1,0): the faces point up
  EXPECT_EQ(normals, "normal_vectors { 5,\n<0,1,0>,\n<0,1,0>,\n<0,1,0>,\n<0,1,0>,\n<0,1,0>") << normals;
  c.normal = {Vec3(1, 0, 0), Vec3::Zero(), Vec3(0, 0, 2), Vec3(0.1f, 0, 0), Vec3(0, 0, -1)};
  // given normals longer than 1/2 are kept (normalised), shorter ones replaced by the triangles' (vertex 3)
  EXPECT_EQ(section(povScene(in), "normal_vectors"),
            "normal_vectors { 5,\n<1,0,0>,\n<0,1,0>,\n<0,0,1>,\n<0,1,0>,\n<0,0,-1>");
}

// water particles are one union of spheres (centre, radius); the surface style draws the surface mesh
// with the water material instead, and neither is drawn for the other style
TEST(RenderPov, WaterAsSpheresOrAsTheSurface) {
  PovFrameInput in;
  in.water = WaterStyle::Particles;
  in.dropCentre = {Vec3(0.1f, 0.2f, 0.3f), Vec3(-1, 0, 2)};
  in.dropRadius = {0.0125f, 0.02f};
  SurfaceMesh s;
  s.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
  s.normals.assign(3, Vec3(0, 1, 0));
  s.triangles = {{0, 2, 1}};
  in.surface = &s;
  const std::string spheres = povScene(in);
  EXPECT_EQ(count(spheres, "\nsphere { "), 2u);
  EXPECT_NE(spheres.find("sphere { <0.1,0.2,0.3>, 0.0125 }"), std::string::npos) << spheres;
  EXPECT_NE(spheres.find("sphere { <-1,0,2>, 0.02 }"), std::string::npos);
  EXPECT_NE(spheres.find("texture { WaterDrop }"), std::string::npos);
  EXPECT_EQ(spheres.find("// water surface"), std::string::npos);
  in.water = WaterStyle::Surface;
  const std::string surface = povScene(in);
  EXPECT_EQ(count(surface, "\nsphere { "), 0u);
  EXPECT_NE(surface.find("// water surface\nmesh2"), std::string::npos);
  EXPECT_NE(surface.find("face_indices { 1,\n<0,2,1> }"), std::string::npos);
  EXPECT_NE(surface.find("material { WaterSurface }"), std::string::npos);
}

// the camera block: POV-Ray's right vector negated (right-handed data) and scaled by the aspect ratio, the
// horizontal angle, and -z as the sky when the camera looks straight down (y would be parallel to it)
TEST(RenderPov, CameraBlockAspectAngleAndSky) {
  PovFrameInput in;
  in.width = 640;
  in.height = 480;
  in.camera.position = Vec3(0, 1, 3);
  in.camera.lookAt = Vec3(0, 0.5f, 0);
  in.camera.fovDegrees = 35.0f;
  const std::string pov = povScene(in);
  EXPECT_NE(pov.find("camera {\n  location <0,1,3>\n  sky <0,1,0>\n  up y\n  right -x*1.33333\n  angle 35\n"
                     "  look_at <0,0.5,0>\n}"),
            std::string::npos)
      << pov;
  in.camera.position = Vec3(0, 5, 0);
  in.camera.lookAt = Vec3(0, 0, 0);
  in.width = 300;
  in.height = 600;
  const std::string down = povScene(in);
  EXPECT_NE(down.find("sky <0,0,-1>"), std::string::npos);
  EXPECT_NE(down.find("right -x*0.5\n"), std::string::npos);
  // a floor when asked, with its checker size
  in.floorY = 0.25f;
  in.checker = 0.2f;
  const std::string floor = povScene(in);
  EXPECT_NE(floor.find("plane { y, 0.25 texture { Floor } }"), std::string::npos);
  EXPECT_NE(floor.find("scale 0.2 }"), std::string::npos);
  EXPECT_EQ(down.find("plane { y,"), std::string::npos);
}

// each collider shape in its local frame under its pose's matrix: a capsule as a cylinder and two
// spheres, a container as its five wall boxes (glass), a mesh collider without a mesh not at all
TEST(RenderPov, EveryColliderShapeIsDrawnInItsLocalFrame) {
  Model m;
  Collider capsule;
  capsule.name = "arm";
  capsule.shape = ColliderShape::Capsule;
  capsule.radius = 0.05f;
  capsule.halfHeight = 0.2f;
  Collider tank;
  tank.name = "tank";
  tank.shape = ColliderShape::Container;
  tank.halfExtents = Vec3(0.3f, 0.2f, 0.25f);
  tank.wallThickness = 0.05f;
  Collider rock;
  rock.name = "rock";
  rock.shape = ColliderShape::Mesh;
  m.colliders = {capsule, tank, rock};
  PovFrameInput in;
  in.model = &m;
  in.poses.resize(3);
  in.poses[0].translation = Vec3(1, 2, 3);
  in.poses[1].rotation = Quat(Eigen::AngleAxisf(0.5f * kPi, Vec3::UnitY()));
  const std::string pov = povScene(in);
  EXPECT_NE(pov.find("// collider arm\nunion {\n  cylinder { <0,-0.2,0>, <0,0.2,0>, 0.05 }\n  sphere { <0,-0.2,0>, 0.05 }\n"
                     "  sphere { <0,0.2,0>, 0.05 }\n  texture { Solid }\n  matrix <1,0,0, 0,1,0, 0,0,1, 1,2,3>\n}"),
            std::string::npos)
      << pov;
  Vec3 centres[kContainerWalls], halves[kContainerWalls];
  containerWalls(tank, centres, halves);
  const size_t at = pov.find("// collider tank\nunion {\n");
  ASSERT_NE(at, std::string::npos) << pov;
  for (int k = 0; k < kContainerWalls; ++k) {
    const Vec3 lo = centres[k] - halves[k], hi = centres[k] + halves[k];
    char box[200];
    std::snprintf(box, sizeof box, "  box { <%.6g,%.6g,%.6g>, <%.6g,%.6g,%.6g> }", lo.x(), lo.y(), lo.z(), hi.x(),
                  hi.y(), hi.z());
    EXPECT_NE(pov.find(box, at), std::string::npos) << box;
  }
  EXPECT_NE(pov.find("texture { Glass }", at), std::string::npos);
  // POV-Ray multiplies row vectors, x' = x M: M's rows are the images of x, y, z, so a quarter turn about
  // y has the row (0, 0, -1) first (x goes to -z), then (0, 1, 0), then (1, 0, 0)
  const size_t mat = pov.find("matrix <", at);
  ASSERT_NE(mat, std::string::npos);
  float e[12];
  ASSERT_EQ(std::sscanf(pov.c_str() + mat, "matrix <%f,%f,%f, %f,%f,%f, %f,%f,%f, %f,%f,%f>", &e[0], &e[1], &e[2], &e[3],
                        &e[4], &e[5], &e[6], &e[7], &e[8], &e[9], &e[10], &e[11]),
            12);
  const float expected[12] = {0, 0, -1, 0, 1, 0, 1, 0, 0, 0, 0, 0};
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(e[k], expected[k], 1e-6f) << k;
  EXPECT_NE(pov.find("// collider rock\n"), std::string::npos);
  EXPECT_EQ(pov.find("// collider rock\nobject"), std::string::npos);
}

// the world bounds: points that are not finite are ignored, an empty box stays empty when added; a
// capsule's bounds follow its rotation, a container's include its walls
TEST(RenderPov, BoundsOfPointsAndColliders) {
  Bounds b;
  EXPECT_TRUE(b.empty());
  b.add(Vec3(std::numeric_limits<float>::quiet_NaN(), 0, 0));
  b.add(Vec3(0, std::numeric_limits<float>::infinity(), 0));
  EXPECT_TRUE(b.empty());
  b.add(Vec3(1, 2, 3), 0.5f);
  b.add(Bounds{});
  EXPECT_EQ(b.lo, Vec3(0.5f, 1.5f, 2.5f));
  EXPECT_EQ(b.hi, Vec3(1.5f, 2.5f, 3.5f));
  Collider capsule;
  capsule.shape = ColliderShape::Capsule;
  capsule.radius = 0.1f;
  capsule.halfHeight = 0.5f;
  ColliderPose lying;
  lying.rotation = Quat(Eigen::AngleAxisf(0.5f * kPi, Vec3::UnitZ()));  // its axis along x
  lying.translation = Vec3(0, 1, 0);
  const Bounds cb = colliderBounds(capsule, lying);
  EXPECT_LT((cb.lo - Vec3(-0.6f, 0.9f, -0.1f)).norm(), 1e-5f);
  EXPECT_LT((cb.hi - Vec3(0.6f, 1.1f, 0.1f)).norm(), 1e-5f);
  Collider tank;
  tank.shape = ColliderShape::Container;
  tank.halfExtents = Vec3(0.3f, 0.2f, 0.25f);
  tank.wallThickness = 0.05f;
  const Bounds tb = colliderBounds(tank, ColliderPose{});
  EXPECT_LT((tb.lo - Vec3(-0.35f, -0.25f, -0.3f)).norm(), 1e-6f);
  EXPECT_LT((tb.hi - Vec3(0.35f, 0.2f, 0.3f)).norm(), 1e-6f);
}

// a Mesh collider without its distance grid has empty bounds, so it does not stretch the camera's framing
TEST(RenderPov, AMeshColliderWithoutItsGridHasNoBounds) {
  Collider mesh;
  mesh.shape = ColliderShape::Mesh;
  const Bounds b = colliderBounds(mesh, ColliderPose{});
  EXPECT_TRUE(b.empty()) << b.lo.transpose() << " .. " << b.hi.transpose();
}

// the cloth's colours: from the saturation on the ramp when there is one per vertex, else the OBJ's
// colours, else none; S^MAX <= 0 draws the dry colour
TEST(RenderPov, ClothColoursFromSaturationElseFromTheObj) {
  ClothFrame c = square();
  c.color = {Vec3(0.1f, 0.2f, 0.3f), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1)};
  EXPECT_EQ(clothColors(c, "red", 0.4f), c.color);
  c.saturation = {0.0f, 0.1f, 0.2f, 0.3f, 0.4f};
  const std::vector<Vec3> g = clothColors(c, "green", 0.4f);
  ASSERT_EQ(g.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(g[i].y(), 1.0f - 0.25f * i, 1e-6f) << i;
  c.saturation.pop_back();  // not one per vertex: the OBJ's colours
  EXPECT_EQ(clothColors(c, "green", 0.4f), c.color);
  EXPECT_EQ(rampColor("red", 0.3f, 0.0f), Vec3(1, 0, 0));
  EXPECT_EQ(rampColor("green", -0.1f, 0.4f), Vec3(0, 1, 0));
}

// names from a scene reach the POV-Ray file only inside comments, escaped: a newline in one would
// end the comment and POV-Ray would run what follows (#system, a #declare ...)
TEST(RenderPov, NamesInCommentsAreEscaped) {
  Scene scene = loadSceneFromString(kTinyScene, "tiny.json", ".");
  scene.model.colliders[0].name = "floor\n#debug \"owned\"\r";
  PovFrameInput in;
  in.model = &scene.model;
  for (const Collider& c : scene.model.colliders) in.poses.push_back(colliderPose(c, 0.0));
  in.title = "tiny\n#include \"/etc/passwd\" frame 1";
  const std::string pov = povScene(in);
  EXPECT_EQ(pov.find("\n#debug"), std::string::npos);
  EXPECT_EQ(pov.find("\n#include"), std::string::npos);
  EXPECT_NE(pov.find("// collider floor\\x0a#debug \"owned\"\\x0d\n"), std::string::npos);
  EXPECT_NE(pov.find("// soak frame: tiny\\x0a#include \"/etc/passwd\" frame 1\n"), std::string::npos);
}

}  // namespace
}  // namespace soak
