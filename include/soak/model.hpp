// Model: everything that stays constant during a run (topology, rest shape, parameters, colliders,
// emitters). Built once by the scene loader; read-only for the step.
#pragma once
#include <soak/garment_params.hpp>
#include <soak/math.hpp>
#include <soak/params.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace soak {

// phase of a particle: 0 is water, k + 1 is cloth piece k (the paper's Flag, section 5)
constexpr int32_t kWaterPhase = 0;
inline bool isWater(int32_t phase) { return phase == kWaterPhase; }
inline int clothPiece(int32_t phase) { return phase - 1; }

// kinematic pose of a collider at a time; rotation then translation maps local to world
struct Keyframe {
  float time = 0.0f;         // s
  Vec3 translation{0, 0, 0}; // m
  Quat rotation{1, 0, 0, 0};
};

// Body: a smooth union of sphere, capsule and box parts, each moved by its own keys (a skinned body:
// the built-in mannequin, docs/mannequin.md)
enum class ColliderShape { Plane, Box, Container, Sphere, Capsule, Mesh, Body, MeshSequence };

// signed distance grid of a closed triangle mesh (src/world/mesh_sdf.hpp); immutable once built
struct SdfGrid;

// frames of one closed mesh topology, an animation (src/world/mesh_sequence.hpp); immutable once read
struct MeshSequence;

// springs, system pattern and wrinkle subdomains of a piece solved implicitly (src/garment/implicit.hpp)
struct GarmentPiece;

struct Collider {
  std::string name;
  ColliderShape shape = ColliderShape::Plane;
  // local-frame geometry: plane y = 0 with normal +y; box / container centred with halfExtents;
  // sphere centred with radius; capsule along local y with halfHeight (segment) and radius
  Vec3 halfExtents{0.5f, 0.5f, 0.5f};  // m
  float radius = 0.5f;                 // m
  float halfHeight = 0.5f;             // m
  float wallThickness = 0.04f;         // m, container walls (open top)
  // mesh: the signed distance grid of a closed OBJ in the local frame, shared by copies of the
  // collider (read-only, so sharing is safe and a Model copy stays cheap)
  std::shared_ptr<const SdfGrid> sdf;
  // body: its parts (sphere, capsule or box colliders; their keys relative to this collider's keys),
  // shared and read-only, and the radius k of the smooth minimum that joins them (m, > 0)
  std::shared_ptr<const std::vector<Collider>> parts;
  float blendRadius = 0.0f;
  // mesh sequence: the frames (local frame), shared and read-only; its keys move it rigidly on top
  std::shared_ptr<const MeshSequence> sequence;
  float friction = 0.3f;               // kinetic Coulomb coefficient, mixed with the particle's (core/friction.hpp)
  float staticFriction = 0.3f;         // static Coulomb coefficient, >= friction
  float restitution = 0.0f;            // 0..1: normal velocity kept, reversed, on contact
  std::vector<Keyframe> keys;          // at least one; linear translation, slerp rotation, clamped ends
};

enum class EmitterKind { Block, Jet, Rain };

struct Emitter {
  std::string name;
  EmitterKind kind = EmitterKind::Block;
  // block: a lattice of particles filling [boxMin, boxMax] at the water spacing, emitted at `start`
  Vec3 boxMin{0, 0, 0}, boxMax{0, 0, 0};  // m
  Vec3 velocity{0, 0, 0};                 // m/s, initial velocity of a block
  // jet: a disc of particles of `radius` at `origin`, moving along `direction` at `speed`
  Vec3 origin{0, 0, 0};
  Vec3 direction{0, -1, 0};  // unit
  float speed = 4.0f;        // m/s (Fig. 1)
  float radius = 0.05f;      // m
  float start = 0.0f;        // s
  float end = 1.0e30f;       // s
  // rain: drops at height origin.y over the rectangle origin +- (halfExtents.x, halfExtents.z),
  // `rate` drops per second per m^2, falling along `direction` at dropSpeed, inside [start, end)
  Vec3 halfExtents{0.5f, 0.0f, 0.5f};  // m (y unused)
  float rate = 200.0f;                 // drops / (s m^2)
  float dropSpeed = 6.5f;              // m/s, terminal speed of a 2 mm drop (Gunn & Kinzer 1949)
  float dropRadius = 0.0f;             // m; 0: a drop is one water particle (water.particleMass)
};

// a cloth piece occupies particles [firstParticle, firstParticle + particleCount) and triangles
// [firstTriangle, firstTriangle + triangleCount); cloth particles come before every water particle
enum class ClothSolver { Pbd, Implicit };

struct ClothPiece {
  std::string name;
  int firstParticle = 0, particleCount = 0;
  int firstTriangle = 0, triangleCount = 0;
  ClothMaterial material;
  // Chen 2012 (docs/garment.md): Implicit pieces are solved by src/garment, not by the PBD stages
  ClothSolver solver = ClothSolver::Pbd;
  GarmentParams garment;            // implicit solver parameters; garment.saturationMass / .saturation
                                    // (Eq. 15-19) also apply to a PBD piece
  bool wetByContact = false;        // the piece keeps a wet start time per vertex (State::clothWetStart)
  bool dropsVanish = true;          // a water particle that wets the piece (no Shao wetting) is taken in
  std::vector<int> panelOfVertex;   // wrinkle subdomains of a procedural garment; empty: patches
  std::vector<std::array<int, 2>> seams;  // local vertex pairs a sewn garment's seams pull together (implicit)
  // Implicit pieces: their constant garment data, built by the scene loader (buildGarmentPieces);
  // shared and read-only, so a Model copy stays cheap
  std::shared_ptr<const GarmentPiece> implicit;
};

// the order the cloth solver projects a set of constraints in (src/pbd/cloth.cpp). The cloth
// particles are cut into numSlabs slabs of equal count along the rest shape's longest axis; the
// constraints are grouped (group g < numSlabs: inside slab g; numSlabs + k: across slabs k and k + 1;
// 2 numSlabs - 1: the rest) and stored group by group, colour by colour. A block (the constraints of
// one colour in one group) shares no particle, nor do the groups of one phase (the slabs; the even
// interfaces; the odd ones): a phase's groups run in parallel and the result does not depend on how
// they are spread over threads.
struct ConstraintSchedule {
  int numSlabs = 0;
  int numColors = 0;               // colours of the greedy colouring the blocks come from
  std::vector<int> groupBlock;     // blocks of group g: [groupBlock[g], groupBlock[g + 1])
  std::vector<int> blockStart;     // constraints of block b: [blockStart[b], blockStart[b + 1])
};

// Eq. 8 constraints as a struct of arrays, stored in the order of their schedule
struct StretchConstraints {
  std::vector<std::array<int, 2>> ids;
  std::vector<float> restLength;   // m
  std::vector<float> compliance;   // m/N (XPBD alpha)
  ConstraintSchedule schedule;
};

// Eq. 9 constraints: ids = {shared edge a, shared edge b, wing c, wing d}
struct BendConstraints {
  std::vector<std::array<int, 4>> ids;
  std::vector<float> restAngle;    // rad, signed dihedral angle at rest
  std::vector<float> compliance;   // 1/(N m)
  ConstraintSchedule schedule;
};

// long range attachments (Kim, Chentanez, Müller 2012): a free cloth particle may be at most
// `length` (its rest path length along the mesh) from each of its anchors, the pinned vertices
// nearest to it; they make a large pinned cloth hang at any iteration count
struct Tethers {
  std::vector<int> start;      // CSR over cloth particles: tethers of i are [start[i], start[i + 1])
  std::vector<int> anchor;     // pinned particle index
  std::vector<float> length;   // m
};

struct Model {
  SolverParams solver;
  WaterParams water;
  WettingParams wetting;

  std::vector<ClothPiece> pieces;
  int numCloth = 0;                              // cloth particles are [0, numCloth)
  std::vector<std::array<int, 3>> triangles;     // cloth triangles, particle indices
  std::vector<Vec3> clothRestPosition;           // m, per cloth particle (initial shape)
  std::vector<float> clothDryMass;               // kg, per cloth particle
  std::vector<float> clothRestArea;              // m^2, per cloth particle: its mixed Voronoi area on the rest mesh
  std::vector<uint8_t> clothPinned;              // 1 = kinematic: stays put (rest position, unless a caller moves it)
  std::vector<uint8_t> clothImplicit;            // 1 = in a piece solved implicitly (moved by src/garment)
  std::vector<int> vertexTriangleStart;          // CSR: triangles around a cloth particle
  std::vector<int> vertexTriangles;
  std::vector<int> vertexNeighborStart;          // CSR: cloth particles sharing an edge (1-ring)
  std::vector<int> vertexNeighbors;              // sorted per particle
  StretchConstraints stretch;
  BendConstraints bend;
  Tethers tethers;

  std::vector<Collider> colliders;
  std::vector<Emitter> emitters;

  // particle i is a cloth particle of a piece solved implicitly (Chen 2012), moved by src/garment only
  bool implicitCloth(int64_t i) const {
    return i >= 0 && i < static_cast<int64_t>(clothImplicit.size()) && clothImplicit[static_cast<size_t>(i)] != 0;
  }
  bool hasImplicitCloth() const {
    for (const ClothPiece& piece : pieces)
      if (piece.solver == ClothSolver::Implicit) return true;
    return false;
  }
};

}  // namespace soak
