// triangle meshes: OBJ reading, generated rectangles, edge lists and cloth mesh checks (mesh.hpp)
#include "world/mesh.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace soak {

namespace {

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

// a token as an error message shows it: at most 40 characters, control bytes as '?'
std::string shown(std::string_view token) {
  std::string s(token.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return "'" + s + (token.size() > 40 ? "...'" : "'");
}

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// the whole token is a finite number (a leading '+' allowed)
bool isFiniteNumber(std::string_view t) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && ec == std::errc() && end == t.data() + t.size() && std::isfinite(v);
}

// a face corner: i, i/j, i//k or i/j/k, each a non-zero integer that fits in 32 bits (j may be empty)
bool isFaceCorner(std::string_view t) {
  int part = 0;
  size_t start = 0;
  for (size_t i = 0; i <= t.size(); ++i) {
    if (i < t.size() && t[i] != '/') continue;
    const std::string_view p = t.substr(start, i - start);
    if (!(part == 1 && p.empty() && i < t.size())) {
      int v = 0;
      const auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), v);
      if (p.empty() || ec != std::errc() || end != p.data() + p.size() || v == 0) return false;
    }
    ++part;
    start = i + 1;
  }
  return part >= 1 && part <= 3;
}

// one v / vn / vt / f line's complaint, or "" when it is well formed
std::string objLineProblem(const std::vector<std::string_view>& w) {
  const std::string_view kind = w[0];
  if (kind == "v" || kind == "vn" || kind == "vt") {
    const size_t lo = kind == "vt" ? 1 : 3, hi = kind == "v" ? 6 : 3;
    const std::string what = kind == "v"    ? "3 finite numbers (x y z, optionally w or r g b) after 'v'"
                             : kind == "vn" ? "3 finite numbers after 'vn'"
                                            : "1 to 3 finite numbers after 'vt'";
    if (w.size() - 1 < lo || w.size() - 1 > hi || (kind == "v" && w.size() - 1 == 5))
      return fmt::format("expected {}, got {} values", what, w.size() - 1);
    for (size_t k = 1; k < w.size(); ++k)
      if (!isFiniteNumber(w[k])) return fmt::format("expected {}, got {}", what, shown(w[k]));
    return "";
  }
  if (kind == "f") {
    if (w.size() < 4) return fmt::format("expected at least 3 vertices after 'f', got {}", w.size() - 1);
    for (size_t k = 1; k < w.size(); ++k)
      if (!isFaceCorner(w[k]))
        return fmt::format("expected face vertices of non-zero integer indices (i, i/j, i//k or i/j/k) after 'f', "
                           "got {}",
                           shown(w[k]));
  }
  return "";
}

}  // namespace

void checkObjText(const std::string& text, const std::string& source) {
  size_t line = 0, begin = 0;
  while (begin < text.size()) {
    ++line;
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string_view l(text.data() + begin, end - begin);
    begin = end + 1;
    if (const size_t hash = l.find('#'); hash != std::string_view::npos) l = l.substr(0, hash);
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ' || l.back() == '\t')) l.remove_suffix(1);
    const std::vector<std::string_view> words = splitWords(l);
    if (words.empty()) continue;
    if (const std::string problem = objLineProblem(words); !problem.empty())
      throw errorAt(source, fmt::format("line {}", line), problem);
  }
}

std::vector<EdgeRef> collectEdges(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<EdgeRef> edges;
  edges.reserve(triangles.size() * 3);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), a, b, c, t});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    return x.triangle < y.triangle;
  });
  return edges;
}

void validateClothMesh(const std::string& name, const TriangleMesh& mesh, const std::vector<int>& pinned,
                       const std::string& source) {
  const std::string where = "cloth '" + name + "'";
  const int nv = static_cast<int>(mesh.vertices.size());
  if (mesh.triangles.empty()) throw errorAt(source, where, "the mesh has no triangles; expected a triangle mesh");
  for (int v = 0; v < nv; ++v)
    if (!mesh.vertices[v].allFinite())
      throw errorAt(source, where + ", vertex " + std::to_string(v), "position is not finite");
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const std::string place = where + ", triangle " + std::to_string(t);
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= nv)
        throw errorAt(source, place,
                      "vertex index " + std::to_string(tri[k]) + " is out of range [0, " + std::to_string(nv) + ")");
    // zero area relative to the longest edge (in double); also catches repeated indices
    const Vec3d a = mesh.vertices[tri[0]].cast<double>(), b = mesh.vertices[tri[1]].cast<double>(),
                c = mesh.vertices[tri[2]].cast<double>();
    const double twiceArea = (b - a).cross(c - a).norm();
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(twiceArea > 1e-6 * longest) || longest == 0.0)
      throw errorAt(source, place,
                    "degenerate triangle (" + std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + ", " +
                        std::to_string(tri[2]) +
                        ") has zero area (height below 1e-6 of its longest edge); expected three " +
                        "distinct, non-collinear vertices");
  }
  const std::vector<EdgeRef> edges = collectEdges(mesh.triangles);
  for (size_t s = 0; s < edges.size();) {
    size_t e = s;
    while (e < edges.size() && edges[e].lo == edges[s].lo && edges[e].hi == edges[s].hi) ++e;
    if (e - s > 2) {
      std::string tris;
      for (size_t k = s; k < e; ++k) tris += (k > s ? ", " : "") + std::to_string(edges[k].triangle);
      throw errorAt(source, where + ", edge (" + std::to_string(edges[s].lo) + ", " + std::to_string(edges[s].hi) + ")",
                    "the edge between vertices " + std::to_string(edges[s].lo) + " and " + std::to_string(edges[s].hi) +
                        " (0-based) is shared by " + std::to_string(e - s) + " triangles (" + tris +
                        "); each edge may be shared by at most two triangles (Shao 2017, section 3.2)");
    }
    s = e;
  }
  for (size_t k = 0; k < pinned.size(); ++k)
    if (pinned[k] < 0 || pinned[k] >= nv)
      throw errorAt(source, where + ", pinned vertex " + std::to_string(k),
                    "vertex index " + std::to_string(pinned[k]) + " is out of range [0, " + std::to_string(nv) + ")");
}

TriangleMesh loadObjMesh(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxObjBytes)
    throw errorAt(path, "", fmt::format("expected an OBJ file of at most {} MiB, got {} bytes", kMaxObjBytes >> 20, size));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw errorAt(path, "", "cannot read OBJ mesh: cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseObjMesh(text.str(), path);
}

TriangleMesh parseObjMesh(const std::string& text, const std::string& path) {
  checkObjText(text, path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = "";
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", config)) {
    const std::string msg = trimmed(reader.Error());
    throw errorAt(path, "", "cannot read OBJ mesh" + (msg.empty() ? std::string() : ": " + msg));
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  TriangleMesh mesh;
  const size_t nv = attrib.vertices.size() / 3;
  mesh.vertices.reserve(nv);
  for (size_t v = 0; v < nv; ++v)
    mesh.vertices.emplace_back(static_cast<float>(attrib.vertices[3 * v]),
                               static_cast<float>(attrib.vertices[3 * v + 1]),
                               static_cast<float>(attrib.vertices[3 * v + 2]));
  // vertices are kept as listed (nothing merged), so OBJ vertex k + 1 is particle k of the piece
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t offset = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t count = shape.mesh.num_face_vertices[f];
      if (count == 3) {
        std::array<int, 3> tri;
        for (int k = 0; k < 3; ++k) {
          tri[k] = shape.mesh.indices[offset + k].vertex_index;
          if (tri[k] < 0 || tri[k] >= static_cast<int>(nv))
            throw errorAt(
                path, "shape '" + shape.name + "', face " + std::to_string(f),
                "vertex index " + std::to_string(tri[k] + 1) + " is out of range [1, " + std::to_string(nv) + "]");
        }
        mesh.triangles.push_back(tri);
      }
      offset += count;
    }
  }
  if (mesh.triangles.empty()) throw errorAt(path, "", "the OBJ file has no triangles; expected a triangle mesh");
  return mesh;
}

TriangleMesh makeRectangle(const Vec3& center, const Vec3& axisU, const Vec3& axisV, float width, float height,
                           int resX, int resY) {
  if (resX < 2 || resY < 2)
    throw Error("makeRectangle: resolution " + std::to_string(resX) + " x " + std::to_string(resY) +
                " must be at least 2 x 2");
  TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(resX) * resY);
  for (int j = 0; j < resY; ++j)
    for (int i = 0; i < resX; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(resX - 1) - 0.5f;
      const float v = static_cast<float>(j) / static_cast<float>(resY - 1) - 0.5f;
      mesh.vertices.push_back(center + (u * width) * axisU + (v * height) * axisV);
    }
  // winding gives every triangle the normal axisU x axisV; diagonals alternate like a checkerboard
  // so the sheet has no preferred shear direction
  mesh.triangles.reserve(static_cast<size_t>(resX - 1) * (resY - 1) * 2);
  for (int j = 0; j + 1 < resY; ++j)
    for (int i = 0; i + 1 < resX; ++i) {
      const int v00 = j * resX + i, v10 = v00 + 1, v01 = v00 + resX, v11 = v01 + 1;
      if ((i + j) % 2 == 0) {
        mesh.triangles.push_back({v00, v10, v11});
        mesh.triangles.push_back({v00, v11, v01});
      } else {
        mesh.triangles.push_back({v00, v10, v01});
        mesh.triangles.push_back({v10, v11, v01});
      }
    }
  return mesh;
}

}  // namespace soak
