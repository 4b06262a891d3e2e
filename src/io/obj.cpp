#include "io/obj.hpp"

#include "core/text.hpp"
#include "io/file.hpp"

#include <fmt/format.h>

namespace soak {

std::vector<Vec3> clothVertexNormals(const Model& model, const std::vector<Vec3>& x) {
  std::vector<Vec3> n(static_cast<size_t>(model.numCloth), Vec3::Zero());
  // summed in triangle order on one thread: the result does not depend on the thread count
  for (const auto& t : model.triangles) {
    const Vec3 areaNormal = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
    for (int k = 0; k < 3; ++k) n[t[k]] += areaNormal;
  }
  for (Vec3& v : n) {
    const float len = v.norm();
    v = len > 0.0f ? Vec3(v / len) : Vec3::Zero();
  }
  return n;
}

static void checkSizes(const std::string& path, const Model& model, const State& state, size_t normals,
                       size_t colors) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  if (state.particles.size() < nc)
    throw Error(path + ": state has " + std::to_string(state.particles.size()) + " particles, model has " +
                std::to_string(nc) + " cloth particles");
  if (normals != 0 && normals != nc)
    throw Error(path + ": expected " + std::to_string(nc) + " normals, got " + std::to_string(normals));
  if (colors != 0 && colors != nc)
    throw Error(path + ": expected " + std::to_string(nc) + " vertex colours, got " + std::to_string(colors));
  // vertices are written piece by piece, so 1-based face indices are particle index + 1 only when the
  // pieces tile [0, numCloth) in order
  int next = 0;
  for (const ClothPiece& piece : model.pieces) {
    if (piece.firstParticle != next)
      throw Error(path + ": cloth piece '" + piece.name + "' starts at particle " +
                  std::to_string(piece.firstParticle) + ", expected " + std::to_string(next));
    next += piece.particleCount;
  }
  if (next != model.numCloth)
    throw Error(path + ": cloth pieces cover " + std::to_string(next) + " particles, expected " +
                std::to_string(model.numCloth));
}

void writeClothObj(const std::string& path, const Model& model, const State& state, std::span<const Vec3> normals,
                   std::span<const Vec3> vertexColor) {
  checkSizes(path, model, state, normals.size(), vertexColor.size());
  std::vector<Vec3> own;
  if (normals.empty()) {
    own = clothVertexNormals(model, state.particles.x);
    normals = own;
  }
  AtomicFile file(path);
  fmt::memory_buffer buf;
  const auto flush = [&] {
    file.out().write(buf.data(), static_cast<std::streamsize>(buf.size()));
    buf.clear();
  };
  fmt::format_to(std::back_inserter(buf), "# soak cloth: {} particles, {} triangles, {} pieces\n", model.numCloth,
                 model.triangles.size(), model.pieces.size());
  const auto& x = state.particles.x;
  for (const ClothPiece& piece : model.pieces) {
    // the name escaped: a newline in it would start lines of geometry of its own
    fmt::format_to(std::back_inserter(buf), "o {}\n", piece.name.empty() ? "cloth" : printableText(piece.name));
    const int end = piece.firstParticle + piece.particleCount;
    for (int i = piece.firstParticle; i < end; ++i) {
      if (vertexColor.empty())
        fmt::format_to(std::back_inserter(buf), "v {} {} {}\n", x[i].x(), x[i].y(), x[i].z());
      else
        fmt::format_to(std::back_inserter(buf), "v {} {} {} {} {} {}\n", x[i].x(), x[i].y(), x[i].z(),
                       vertexColor[i].x(), vertexColor[i].y(), vertexColor[i].z());
    }
    for (int i = piece.firstParticle; i < end; ++i)
      fmt::format_to(std::back_inserter(buf), "vn {} {} {}\n", normals[i].x(), normals[i].y(), normals[i].z());
    const int tEnd = piece.firstTriangle + piece.triangleCount;
    for (int t = piece.firstTriangle; t < tEnd; ++t) {
      const auto& tri = model.triangles[t];
      fmt::format_to(std::back_inserter(buf), "f {0}//{0} {1}//{1} {2}//{2}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    if (buf.size() > (1u << 20)) flush();
  }
  flush();
  file.commit();
}

}  // namespace soak
