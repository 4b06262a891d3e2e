// scene keys of the Chen 2012 models (docs/scene-format.md, "Garments"): mannequin and mesh colliders,
// rain, procedural garments, and a cloth piece's solver, fabric, saturation and garment settings
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"
#include "scene/reader.hpp"
#include "world/mannequin.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace soak {

// a mannequin entry of the scene, kept by name for the garments sewn around it
struct BodySpec {
  MannequinParams params;
  std::vector<PoseKey> keys;
  std::vector<Collider> colliders;
};
using Bodies = std::map<std::string, BodySpec>;

// a "mannequin" collider entry (r is the entry, its name and type already read): the colliders,
// one smooth body <name> (blend > 0) or its parts <name>.head ... <name>.foot_r (mannequinColliders),
// also remembered in bodies[name]. Empty when invalid (logged).
std::vector<Collider> readMannequin(ObjectReader& r, const std::string& name, Bodies& bodies);

// the shape keys of a "mesh" collider (path, resolution, padding): sets c.sdf; false when invalid
bool readMeshColliderShape(ObjectReader& r, Collider& c, const std::string& baseDir);

// the shape keys of a "meshSequence" collider (path with '#' for the frame number, fps, start,
// scale, firstFrame, lastFrame): reads the frames into c.sequence; false when invalid (logged)
bool readMeshSequenceShape(ObjectReader& r, Collider& c, const std::string& baseDir);

// the keys of a "rain" emitter (origin, halfExtents, rate, dropSpeed, dropRadius, direction, start, end)
void readRain(ObjectReader& r, Emitter& e);

// a cloth mesh of "type": "garment" sewn around a mannequin of `bodies` (the reader r is the mesh
// object, its type read); panelOfVertex gets the garment's panels. nullopt when invalid (logged)
std::optional<TriangleMesh> readGarmentMesh(ObjectReader& r, const Bodies& bodies, std::vector<int>& panelOfVertex);
extern const std::vector<std::string> kGarmentMeshKeys;

// the Chen 2012 settings of a cloth piece
struct ChenClothSpec {
  ClothSolver solver = ClothSolver::Pbd;
  GarmentParams garment;
  bool wetByContact = false;
  bool dropsVanish = true;
  bool wetAtStart = false;  // every vertex wet from t = 0 (a soaked fabric)
  // "body": the piece must start outside these colliders by `bodyMargin` (pushed out, or refused);
  // a negative margin is resolved to half the piece's thickness by the caller
  std::string body;
  float bodyMargin = -1.0f;
  bool pushOut = true;
};

// reads "solver" of cloth[k] (pbd when invalid, logged)
ClothSolver readClothSolver(ObjectReader& r);
// reads "fabric", "saturation", "garment" and "body" of cloth[k] for a piece of the given solver
ChenClothSpec readChenCloth(ObjectReader& r, ClothSolver solver, bool shaoWetting);

// checks a piece's mesh against its "body": pushes vertices out (pushOut) or refuses them, naming
// the vertices; errors go to log at path
void checkOutsideBody(ErrorLog& log, const std::string& path, const ChenClothSpec& spec, const Bodies& bodies,
                      const std::vector<Collider>& colliders, TriangleMesh& mesh);

}  // namespace soak
