// POV-Ray scene text of one frame (docs/rendering.md)
#include "render/pov.hpp"

#include "core/text.hpp"
#include "wetting/wetting.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "world/container.hpp"
#include "world/mesh_sdf.hpp"

namespace soak {

namespace {

const Vec3 kFabric(0.80f, 0.74f, 0.62f);  // plain cloth without saturation
const Vec3 kColliderColor(0.55f, 0.60f, 0.68f);

using Buf = fmt::memory_buffer;

void v3(Buf& b, const Vec3& v) { fmt::format_to(std::back_inserter(b), "<{:.6g},{:.6g},{:.6g}>", v.x(), v.y(), v.z()); }

// POV-Ray multiplies row vectors: x' = x M, so its 3x3 part is the transpose of R
void transform(Buf& b, const ColliderPose& pose) {
  const Eigen::Matrix3f r = pose.rotation.toRotationMatrix();
  const Vec3& t = pose.translation;
  fmt::format_to(std::back_inserter(b),
                 "  matrix <{:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}, {:.7g},{:.7g},{:.7g}>\n",
                 r(0, 0), r(1, 0), r(2, 0), r(0, 1), r(1, 1), r(2, 1), r(0, 2), r(1, 2), r(2, 2), t.x(), t.y(), t.z());
}

// a vertex without a usable normal gets one from its triangles (or +y) so POV-Ray shades it
std::vector<Vec3> usableNormals(const std::vector<Vec3>& x, const std::vector<Vec3>& given,
                                const std::vector<std::array<int, 3>>& tris) {
  std::vector<Vec3> n(x.size(), Vec3::Zero());
  for (const auto& t : tris) {
    const Vec3 f = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
    for (int k = 0; k < 3; ++k) n[t[k]] += f;
  }
  for (size_t i = 0; i < n.size(); ++i) {
    const Vec3& g = i < given.size() ? given[i] : Vec3::Zero();
    const Vec3& use = g.squaredNorm() > 0.25f ? g : n[i];
    const float len = use.norm();
    n[i] = len > 1e-20f && std::isfinite(len) ? Vec3(use / len) : Vec3(0, 1, 0);
  }
  return n;
}

void mesh2(Buf& b, const std::vector<Vec3>& x, const std::vector<Vec3>& normals,
           const std::vector<std::array<int, 3>>& tris, const std::vector<Vec3>& color, const char* material) {
  b.append(std::string_view("mesh2 {\n  vertex_vectors { "));
  fmt::format_to(std::back_inserter(b), "{}", x.size());
  for (const Vec3& p : x) {
    b.append(std::string_view(",\n"));
    v3(b, p);
  }
  fmt::format_to(std::back_inserter(b), " }}\n  normal_vectors {{ {}", normals.size());
  for (const Vec3& n : normals) {
    b.append(std::string_view(",\n"));
    v3(b, n);
  }
  b.append(std::string_view(" }\n"));
  const bool perVertex = color.size() == x.size();
  if (perVertex) {
    fmt::format_to(std::back_inserter(b), "  texture_list {{ {}", color.size());
    for (const Vec3& c : color)
      fmt::format_to(std::back_inserter(b),
                     ",\n texture {{ pigment {{ srgb <{:.4f},{:.4f},{:.4f}> }} finish {{ ClothFinish }} }}", c.x(),
                     c.y(), c.z());
    b.append(std::string_view(" }\n"));
  }
  fmt::format_to(std::back_inserter(b), "  face_indices {{ {}", tris.size());
  for (const auto& t : tris) {
    if (perVertex)
      fmt::format_to(std::back_inserter(b), ",\n<{0},{1},{2}>,{0},{1},{2}", t[0], t[1], t[2]);
    else
      fmt::format_to(std::back_inserter(b), ",\n<{},{},{}>", t[0], t[1], t[2]);
  }
  b.append(std::string_view(" }\n"));
  fmt::format_to(std::back_inserter(b), "  {}\n}}\n", material);
}

void box(Buf& b, const Vec3& centre, const Vec3& half) {
  b.append(std::string_view("  box { "));
  v3(b, centre - half);
  b.append(std::string_view(", "));
  v3(b, centre + half);
  b.append(std::string_view(" }\n"));
}

void collider(Buf& b, const Collider& c, const ColliderPose& pose, const SurfaceMesh* mesh) {
  // names escaped: a newline would end the comment and POV-Ray would run the rest
  fmt::format_to(std::back_inserter(b), "// collider {}\n", printableText(c.name));
  switch (c.shape) {
    case ColliderShape::Mesh:
      // the zero level of its distance grid, meshed once (render.cpp), in the local frame
      if (mesh == nullptr || mesh->triangles.empty()) return;
      b.append(std::string_view("object {\n"));
      mesh2(b, mesh->vertices, usableNormals(mesh->vertices, mesh->normals, mesh->triangles), mesh->triangles, {},
            "texture { Solid }");
      break;
    case ColliderShape::Body:
    case ColliderShape::MeshSequence:
      // a body's smooth skin, a sequence's surface, at this frame's pose in the world frame (render.cpp)
      if (mesh == nullptr || mesh->triangles.empty()) return;
      b.append(std::string_view("object {\n"));
      mesh2(b, mesh->vertices, usableNormals(mesh->vertices, mesh->normals, mesh->triangles), mesh->triangles, {},
            "texture { Solid }");
      b.append(std::string_view("}\n"));
      return;
    case ColliderShape::Plane: {
      const Vec3 n = pose.rotation * Vec3(0, 1, 0);
      b.append(std::string_view("plane { "));
      v3(b, n);
      fmt::format_to(std::back_inserter(b), ", {:.7g} texture {{ Floor }} }}\n", n.dot(pose.translation));
      return;
    }
    case ColliderShape::Box:
      b.append(std::string_view("object {\n"));
      box(b, Vec3::Zero(), c.halfExtents);
      b.append(std::string_view("  texture { Solid }\n"));
      break;
    case ColliderShape::Container: {
      Vec3 centres[kContainerWalls], halves[kContainerWalls];
      containerWalls(c, centres, halves);
      b.append(std::string_view("union {\n"));
      for (int k = 0; k < kContainerWalls; ++k) box(b, centres[k], halves[k]);
      // see-through walls so the water inside shows
      b.append(std::string_view("  texture { Glass }\n"));
      break;
    }
    case ColliderShape::Sphere:
      fmt::format_to(std::back_inserter(b), "sphere {{ <0,0,0>, {:.7g}\n  texture {{ Solid }}\n", c.radius);
      break;
    case ColliderShape::Capsule:
      fmt::format_to(
          std::back_inserter(b),
          "union {{\n  cylinder {{ <0,{0:.7g},0>, <0,{1:.7g},0>, {2:.7g} }}\n  sphere {{ <0,{0:.7g},0>, {2:.7g} }}\n"
          "  sphere {{ <0,{1:.7g},0>, {2:.7g} }}\n  texture {{ Solid }}\n",
          -c.halfHeight, c.halfHeight, c.radius);
      break;
  }
  transform(b, pose);
  b.append(std::string_view("}\n"));
}

}  // namespace

void Bounds::add(const Vec3& p, float pad) {
  if (!p.allFinite()) return;
  lo = lo.cwiseMin(p - Vec3::Constant(pad));
  hi = hi.cwiseMax(p + Vec3::Constant(pad));
}

void Bounds::add(const Bounds& b) {
  if (b.empty()) return;
  lo = lo.cwiseMin(b.lo);
  hi = hi.cwiseMax(b.hi);
}

Bounds colliderBounds(const Collider& c, const ColliderPose& pose) {
  Bounds world;
  Vec3 lo, hi;
  if (!colliderBox(c, pose, &lo, &hi)) return world;  // a plane, or a mesh without its distance grid
  world.add(lo);
  world.add(hi);
  return world;
}

CameraFit::CameraFit(const CameraRequest& req, int width, int height) : request_(req) {
  const float az = req.azimuthDegrees * kPi / 180.0f, el = req.elevationDegrees * kPi / 180.0f;
  toCamera_ = Vec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
  // camera axes: right and up of a camera looking along -toCamera with y as the sky
  right_ = Vec3(0, 1, 0).cross(toCamera_);
  right_ = right_.norm() < 1e-6f ? Vec3(1, 0, 0) : Vec3(right_.normalized());
  up_ = toCamera_.cross(right_).normalized();
  tanH_ = std::tan(0.5f * req.fovDegrees * kPi / 180.0f);
  tanV_ = tanH_ * static_cast<float>(height) / static_cast<float>(width);
  // a point is in the picture when |x| <= (dist - z) tan: dist >= (p - c) . (toCamera +- right / tan)
  direction_[0] = toCamera_ + right_ / tanH_;
  direction_[1] = toCamera_ - right_ / tanH_;
  direction_[2] = toCamera_ + up_ / tanV_;
  direction_[3] = toCamera_ - up_ / tanV_;
}

void CameraFit::add(const Vec3& p, float pad) {
  if (!p.allFinite()) return;
  bounds_.add(p, pad);
  for (int k = 0; k < 4; ++k) support_[k] = std::max(support_[k], p.dot(direction_[k]) + pad * direction_[k].norm());
}

void CameraFit::add(const Bounds& b) {
  if (b.empty()) return;
  for (int k = 0; k < 8; ++k)
    add(Vec3((k & 1) ? b.hi.x() : b.lo.x(), (k & 2) ? b.hi.y() : b.lo.y(), (k & 4) ? b.hi.z() : b.lo.z()));
}

CameraSpec CameraFit::camera() const {
  if (bounds_.empty()) {
    // nothing to show: a unit box at the origin
    CameraFit unit = *this;
    Bounds b;
    b.add(Vec3::Zero(), 0.5f);
    unit.add(b);
    return unit.camera();
  }
  CameraSpec cam;
  cam.fovDegrees = request_.fovDegrees;
  const Vec3 centre = 0.5f * (bounds_.lo + bounds_.hi);
  cam.lookAt = request_.lookAt.value_or(centre);
  if (request_.position) {
    cam.position = *request_.position;
    return cam;
  }
  float dist = 0.0f;
  for (int k = 0; k < 4; ++k) dist = std::max(dist, support_[k] - cam.lookAt.dot(direction_[k]));
  const float size = (bounds_.hi - bounds_.lo).norm();
  dist = std::max(dist * 1.06f, 0.05f * size + 1e-3f) / request_.zoom;
  cam.position = cam.lookAt + dist * toCamera_;
  return cam;
}

CameraSpec frameCamera(const Bounds& bounds, const CameraRequest& request, int width, int height) {
  CameraFit fit(request, width, height);
  fit.add(bounds);
  return fit.camera();
}

std::vector<Vec3> clothColors(const ClothFrame& cloth, const std::string& ramp, float saturationMax) {
  if (cloth.saturation.size() == cloth.x.size() && !cloth.x.empty()) {
    std::vector<Vec3> c(cloth.x.size());
    for (size_t i = 0; i < c.size(); ++i) c[i] = rampColor(ramp, cloth.saturation[i], saturationMax);
    return c;
  }
  return cloth.color;
}

std::string povScene(const PovFrameInput& in) {
  Buf b;
  const CameraSpec& cam = in.camera;
  const float aspect = static_cast<float>(in.width) / static_cast<float>(in.height);
  fmt::format_to(std::back_inserter(b), "// soak frame: {}\n#version 3.7;\n", printableText(in.title));
  b.append(
      std::string_view("global_settings { assumed_gamma 1.0 max_trace_level 12 ambient_light rgb <1,1,1> }\n"
                       "#declare ClothFinish = finish { ambient 0.12 diffuse 0.8 specular 0.08 roughness 0.05 }\n"
                       "#declare Solid = texture { pigment { rgb "));
  v3(b, kColliderColor);
  b.append(std::string_view(
      " } finish { ambient 0.12 diffuse 0.75 specular 0.3 roughness 0.02 } }\n"
      "#declare Glass = texture { pigment { rgbt <0.80,0.86,0.92,0.75> } finish { ambient 0.1 diffuse 0.3 specular 0.6 "
      "roughness 0.01 } }\n"
      "#declare WaterSurface = material { texture { pigment { rgbf <0.70,0.85,1.0,0.75> }\n"
      "  finish { ambient 0.05 diffuse 0.25 specular 0.9 roughness 0.003 reflection 0.08 } } interior { ior 1.33 } }\n"
      "#declare WaterDrop = texture { pigment { rgb <0.16,0.42,0.85> } finish { ambient 0.15 diffuse 0.7 specular 0.6 "
      "roughness 0.01 } }\n"));
  fmt::format_to(
      std::back_inserter(b),
      "#declare Floor = texture {{ pigment {{ checker rgb <0.78,0.78,0.76> rgb <0.62,0.63,0.64> scale {:.6g} }}\n"
      "  finish {{ ambient 0.12 diffuse 0.8 }} }}\n",
      in.checker);
  b.append(
      std::string_view("sky_sphere { pigment { gradient y color_map { [0.0 rgb <0.93,0.94,0.96>] [1.0 rgb "
                       "<0.55,0.68,0.86>] } scale 2 translate -1 } }\n"));
  // right-handed data: a negative right vector (POV-Ray documentation, "camera")
  b.append(std::string_view("camera {\n  location "));
  v3(b, cam.position);
  // y is the sky, unless the camera looks straight up or down: then -z is up in the picture
  const Vec3 dir = (cam.lookAt - cam.position).normalized();
  const char* sky = std::abs(dir.y()) > 0.9999f ? "<0,0,-1>" : "<0,1,0>";
  fmt::format_to(std::back_inserter(b), "\n  sky {}\n  up y\n  right -x*{:.6g}\n  angle {:.6g}\n  look_at ", sky,
                 aspect, cam.fovDegrees);
  v3(b, cam.lookAt);
  b.append(std::string_view("\n}\n"));
  // a key light above and to the left of the camera, a soft fill from its right
  const Vec3 view = cam.position - cam.lookAt;
  const float dist = std::max(view.norm(), 1e-3f);
  Vec3 right = Vec3(0, 1, 0).cross(view);
  right = right.norm() > 1e-6f ? Vec3(right.normalized()) : Vec3(1, 0, 0);
  const Vec3 key = cam.lookAt + view + dist * (Vec3(0, 1.2f, 0) - 0.8f * right);
  const Vec3 fill = cam.lookAt + view + dist * (0.9f * right + Vec3(0, 0.3f, 0));
  b.append(std::string_view("light_source { "));
  v3(b, key);
  b.append(std::string_view(" color rgb <1.0,0.98,0.95> }\nlight_source { "));
  v3(b, fill);
  b.append(std::string_view(" color rgb <0.35,0.37,0.42> shadowless }\n"));

  if (in.floorY) fmt::format_to(std::back_inserter(b), "plane {{ y, {:.7g} texture {{ Floor }} }}\n", *in.floorY);
  if (in.model != nullptr)
    for (size_t k = 0; k < in.model->colliders.size() && k < in.poses.size(); ++k)
      collider(b, in.model->colliders[k], in.poses[k], k < in.colliderMesh.size() ? in.colliderMesh[k] : nullptr);

  if (in.cloth != nullptr && !in.cloth->triangles.empty()) {
    const ClothFrame& c = *in.cloth;
    b.append(std::string_view("// cloth\n"));
    const std::string plain =
        fmt::format("texture {{ pigment {{ srgb <{:.4f},{:.4f},{:.4f}> }} finish {{ ClothFinish }} }}", kFabric.x(),
                    kFabric.y(), kFabric.z());
    mesh2(b, c.x, usableNormals(c.x, c.normal, c.triangles), c.triangles, in.clothColor,
          in.clothColor.size() == c.x.size() ? "" : plain.c_str());
  }
  if (in.water == WaterStyle::Surface && in.surface != nullptr && !in.surface->triangles.empty()) {
    const SurfaceMesh& s = *in.surface;
    b.append(std::string_view("// water surface\n"));
    mesh2(b, s.vertices, usableNormals(s.vertices, s.normals, s.triangles), s.triangles, {},
          "inside_vector <0,0,1>\n  material { WaterSurface }");
  }
  if (in.water == WaterStyle::Particles && !in.dropCentre.empty()) {
    b.append(std::string_view("// water particles\nunion {\n"));
    for (size_t i = 0; i < in.dropCentre.size(); ++i) {
      b.append(std::string_view("sphere { "));
      v3(b, in.dropCentre[i]);
      fmt::format_to(std::back_inserter(b), ", {:.5g} }}\n", in.dropRadius[i]);
    }
    b.append(std::string_view("  texture { WaterDrop }\n}\n"));
  }
  return fmt::to_string(b);
}

}  // namespace soak
