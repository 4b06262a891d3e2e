// a "cloth" entry of the scene file (docs/scene-format.md): its mesh (rectangle, OBJ file or garment),
// material, pinned vertices and Chen 2012 settings, read and checked into a ClothSpec
#pragma once
#include <soak/model.hpp>

#include "scene/chen_keys.hpp"
#include "scene/limits.hpp"
#include "scene/reader.hpp"
#include "world/mesh.hpp"

#include <optional>
#include <string>
#include <vector>

namespace soak {

// a validated cloth piece waiting to be appended to the model
struct ClothSpec {
  std::string name;
  std::string path;  // JSON path of the piece, for build-time errors
  TriangleMesh mesh;
  ClothMaterial material;
  std::vector<int> pinned;  // mesh vertex indices, sorted, unique
  ChenClothSpec chen;       // solver, saturation mass, garment settings (Chen 2012)
  std::vector<int> panelOfVertex;
  std::vector<std::array<int, 2>> seams;  // a sewn garment's vertex pairs (mesh indices)
};

// reads cloth[index] (v, at JSON path `path`); nullopt when it is invalid (errors logged). Meshes
// have at most limit.count vertices; a garment is sewn around a mannequin of `bodies`, and a piece
// with a "body" is checked against (or pushed out of) the colliders
std::optional<ClothSpec> readCloth(ErrorLog& log, const Json& v, const std::string& path, int index,
                                   const std::string& baseDir, const ParticleLimit& limit, bool shaoWetting, const Bodies& bodies,
                                   const std::vector<Collider>& colliders);

}  // namespace soak
