// cloth as Wavefront OBJ: one file for all cloth, one `o <piece name>` group per piece
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <span>
#include <string>
#include <vector>

namespace soak {

// area-weighted vertex normals of the cloth particles [0, model.numCloth): the sum of the
// unnormalised face normals (twice the area times the unit normal) around each vertex, normalised;
// zero for a vertex with no (non-degenerate) triangle
std::vector<Vec3> clothVertexNormals(const Model& model, const std::vector<Vec3>& x);

// writes every cloth particle as `v x y z` (or `v x y z r g b` when vertexColor has one colour per
// cloth particle, components 0..1), its normal as `vn`, and the triangles as 1-based `f a//a b//b c//c`.
// normals: one per cloth particle, or empty to compute them here. Throws soak::Error naming the file.
void writeClothObj(const std::string& path, const Model& model, const State& state,
                   std::span<const Vec3> normals = {}, std::span<const Vec3> vertexColor = {});

}  // namespace soak
