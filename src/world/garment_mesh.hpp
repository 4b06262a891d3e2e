// procedural garments for the mannequin: a T-shirt or a dress as one closed-seam triangle mesh,
// sewn from panels (front, back, sleeves) whose ids are Chen 2012's wrinkle subdomains (section 3.5)
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"
#include "world/colliders.hpp"
#include "world/mannequin.hpp"

#include <string>
#include <vector>

namespace soak {

enum class GarmentStyle { TShirt, Dress };

struct GarmentPattern {
  GarmentStyle style = GarmentStyle::TShirt;
  float edgeLength = 0.03f;    // m, target spacing of the panel grids
  float margin = 0.01f;        // m, least distance of every vertex from the body at the start
  float ease = 0.02f;          // m, looseness added to the margin where the cloth hugs the body
  float hem = 0.0f;            // height of the hem / body height; 0: the style's (tshirt 0.48, dress 0.25)
  float sleeveLength = 0.6f;   // tshirt: sleeve length / upper arm length, in (0, 1]
  float neckOpening = 0.03f;   // m, neck hole half-width beyond the neck radius + margin + ease
  float flare = 0.2f;          // rad, dress: skirt widening below the hips
};

// panel ids: 0 front, 1 back, 2 left sleeve, 3 right sleeve; a seam vertex belongs to the lowest panel
// that holds it (front before back; a sleeve's seam vertices to the sleeve)
constexpr int kPanelFront = 0, kPanelBack = 1, kPanelLeftSleeve = 2, kPanelRightSleeve = 3;

struct Garment {
  TriangleMesh mesh;                   // world frame, m; front faces outward
  std::vector<int> panelOfVertex;      // one panel id per vertex
  std::vector<std::string> panelNames; // indexed by panel id
};

// sews the garment around the body standing in `pose`: front and back panels over a T (tshirt) or
// a tube with armholes (dress), each vertex projected onto the body's front / back offset surface
// (margin + ease), seams at the body's mid plane outside its silhouette, then pushed out of the
// body. Every edge is in one or two triangles. Throws soak::Error (naming `source`) when the
// parameters are out of range or the arms are too close to the body for the style (tshirt: raise
// shoulderAbduction; 0.7 rad works at default proportions, the dress needs 0.3 rad).
Garment buildGarment(const MannequinParams& body, const MannequinPose& pose, const GarmentPattern& params,
                     const std::string& source = "garment");

// the body's colliders posed once at time t, for many queries (a mesh sequence builds its surface
// tree when posed)
struct PosedBody {
  PosedBody(const std::vector<Collider>& body, double t);
  // the union's signed distance (m), with the nearest collider's outward normal (may be null)
  float distance(const Vec3& p, Vec3* normal) const;
  const std::vector<Collider>* colliders;
  std::vector<ColliderPose> poses;
};

// PosedBody(body, t).distance(p, normal): for one query
float bodyDistance(const std::vector<Collider>& body, double t, const Vec3& p, Vec3* normal);

// indices of the vertices closer to the body than `margin` (minus 1e-5 m for rounding)
std::vector<int> verticesInsideBody(const TriangleMesh& mesh, const std::vector<Collider>& body, double t,
                                    float margin);

// moves each vertex closer than `margin` out along the body's normal, up to `iterations` times;
// one still inside (pushed back and forth between two parts) takes the shortest way out along 26
// directions. Returns how many are still closer than margin
size_t pushOutOfBody(TriangleMesh& mesh, const std::vector<Collider>& body, double t, float margin,
                     int iterations = 8);

}  // namespace soak
