// checkpoints: the whole State of a run and what its frame loop carries between two steps, in a
// versioned binary file, so a killed or extended run continues exactly where it stopped
// (docs/output-format.md "checkpoint.soak"; `soak run --checkpoint-every`, `soak resume`)
#pragma once
#include <soak/model.hpp>
#include <soak/output.hpp>
#include <soak/state.hpp>

#include <cstdint>
#include <string>
#include <string_view>

namespace soak {

// bumped whenever the file's layout or the State's fields change; a file of another format is refused
inline constexpr uint32_t kCheckpointFormat = 2;

// where in the run a checkpoint's state is
struct CheckpointInfo {
  std::string soakVersion;   // the program that wrote it; a resume by another version is refused
  uint64_t sceneHash = 0;    // textHash of the scene as run (the run folder's scene.json)
  int frame = 0;             // the last frame written before this state
  int stepsIntoFrame = 0;    // steps of frame + 1 already taken (0: the state is frame's)
  FrameStats frameSoFar;     // those steps' statistics, so frame + 1's stats line stays whole
};

struct Checkpoint {
  CheckpointInfo info;
  State state;
};

// 64-bit FNV-1a of a text (the scene a checkpoint belongs to)
uint64_t textHash(std::string_view text);

// writes `info` and `state` to `path` atomically (path.part, then renamed); throws soak::Error naming the file
void writeCheckpoint(const std::string& path, const CheckpointInfo& info, const State& state);

// reads a checkpoint. Throws soak::Error naming the file when it is not a soak checkpoint, is of
// another format, is truncated or corrupt (no array is allocated beyond the file's size, and the
// state read back must hash to the hash stored with it)
Checkpoint readCheckpoint(const std::string& path);

// throws soak::Error naming `path` when the checkpoint's state cannot belong to `model` (cloth
// particle count and phases, emitters, the wetting arrays' sizes)
void checkCheckpointFits(const std::string& path, const Checkpoint& c, const Model& model);

}  // namespace soak
