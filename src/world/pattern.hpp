// garments sewn from 2-D pattern panels, as garment tools make them (docs/mannequin.md, "Sewing
// patterns"): each panel's outline is sampled at the chosen edge length, triangulated by CGAL's
// constrained Delaunay mesher without Steiner points on the outline, and placed in 3-D around the body;
// a seam joins two stretches of outline and pairs their boundary vertices one to one. The implicit
// solver pulls each pair together while the seams close (seam springs, garment/springs.hpp).
#pragma once
#include <soak/math.hpp>

#include "world/mesh.hpp"

#include <array>
#include <string>
#include <vector>

namespace soak {

using Vec2d = Eigen::Vector2d;

// one panel: an outline in its own plane (u to the right, v up, seen from the garment's outside) and
// where it goes. A point (u, v) is placed at origin + u' right + v up + w' outward, with right =
// (cos yaw, 0, -sin yaw) and outward = right x up; a flat panel has u' = u, w' = 0, a bent one is wrapped
// on a vertical cylinder of radius `bend` whose axis lies `bend` behind the origin:
// u' = bend sin(u / bend), w' = bend (cos(u / bend) - 1)
struct PatternPanel {
  std::string name;
  std::vector<Vec2d> outline;  // m, counter-clockwise corners, no repeated end point, no self-crossing
  Vec3d origin = Vec3d::Zero();  // m, where (u, v) = (0, 0) goes
  double yaw = 0.0;              // rad about +y; 0: the panel faces +z, pi: it faces -z
  double bend = 0.0;             // m, > 0 wraps the panel around the body; 0 flat
};

// the outline of panel `panel` from corner `from` to corner `to`, counter-clockwise (it may wrap past
// the last corner)
struct PatternEdge {
  int panel = 0;
  int from = 0, to = 0;
};

// a seam joins a's stretch to b's: a's first point to b's last (two panels seen from outside run
// along a shared seam in opposite directions), or to b's first when `reverse`
struct PatternSeam {
  PatternEdge a, b;
  bool reverse = false;
};

struct SewingPattern {
  std::vector<PatternPanel> panels;
  std::vector<PatternSeam> seams;
};

struct SewnGarment {
  TriangleMesh mesh;                        // every panel, placed; front faces outward
  std::vector<int> panelOfVertex;           // index into panelNames
  std::vector<std::string> panelNames;
  std::vector<std::array<int, 2>> seamPairs;  // vertex pairs the seams pull together, sorted, unique
};

// the vertices a triangulation of `pattern` at `edgeLength` will have, about (the panels' area over
// an equilateral triangle's share), for limits checked before any meshing
double estimatedPatternVertices(const SewingPattern& pattern, double edgeLength);

// checks the pattern (outlines counter-clockwise and simple, seams on existing corners, no outline
// segment in two seams) and triangulates it: every outline segment is split into pieces of at most
// edgeLength (a seam's two sides into the same number, at the same arc-length fractions, keeping the
// corners of both), interior triangles have edges of about edgeLength and angles of at least 20.7
// degrees. Throws soak::Error "<source>.panels[i]...: expected ..., got ..." on bad input (a source
// ending in a space, "<file>: at ", gives "<file>: at panels[i]...").
SewnGarment sewPattern(const SewingPattern& pattern, double edgeLength, const std::string& source);

}  // namespace soak
