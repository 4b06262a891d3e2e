// the files of one frame in an output directory, as chosen by the scene's OutputSettings
#pragma once
#include <soak/model.hpp>
#include <soak/scene.hpp>
#include <soak/state.hpp>

#include "io/ply.hpp"

#include <span>
#include <string>
#include <vector>

namespace soak {

// writes dir/cloth_NNNN.obj, dir/cloth_NNNN.ply and dir/water_NNNN.ply as enabled in `settings`
// (cloth files only when the model has cloth). clothExtras are added to the cloth PLY, clothColors
// (one per cloth particle, 0..1) to the cloth OBJ's vertices. Returns the paths written. Throws
// soak::Error naming the file that failed.
std::vector<std::string> writeFrameFiles(const std::string& dir, const Model& model, const State& state,
                                         const OutputSettings& settings, int frame,
                                         std::span<const PlyFloatAttribute> clothExtras = {},
                                         std::span<const Vec3> clothColors = {});

}  // namespace soak
