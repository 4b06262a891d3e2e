// `soak resume DIR`: continue a run from DIR/checkpoint.soak, with the scene as run (DIR/scene.json)
// and run.json's settings; the frames and stats lines after the checkpoint are replaced
#include "commands.hpp"

#include <soak/checkpoint.hpp>
#include <soak/error.hpp>
#include <soak/threads.hpp>

#include "frame_loop.hpp"
#include "progress.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <regex>
#include <sstream>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;

nlohmann::ordered_json readRunJson(const fs::path& dir) {
  const fs::path path = dir / "run.json";
  if (!fs::is_regular_file(path)) throw Error(dir.string() + ": no run.json: not the output folder of soak run");
  try {
    return nlohmann::ordered_json::parse(readTextFile(path.string()));
  } catch (const nlohmann::json::exception& e) {
    throw Error(path.string() + ": not valid JSON: " + e.what());
  }
}

// the checkpoint, checked against this program and the folder's scene.json (loaded into `scene`)
Checkpoint readMatchingCheckpoint(const fs::path& dir, Scene& scene) {
  const std::string path = (dir / kCheckpointFile).string();
  if (!fs::exists(path))
    throw Error(dir.string() + ": no " + kCheckpointFile + " to resume from (run with --checkpoint-every N, or stop "
                "the run with SIGINT / SIGTERM, to have one)");
  Checkpoint c = readCheckpoint(path);
  if (c.info.soakVersion != kVersion)
    throw Error(fmt::format("{}: written by soak {}, this is soak {}: resume it with the version that started it", path,
                            c.info.soakVersion, kVersion));
  const std::string scenePath = (dir / "scene.json").string();
  const std::string text = readTextFile(scenePath);
  if (textHash(text) != c.info.sceneHash)
    throw Error(path + ": the checkpoint belongs to another scene: " + scenePath +
                " changed after the run wrote it (restore it, or start a new run)");
  scene = loadSceneFromString(text, scenePath, dir.string());
  checkCheckpointFits(path, c, scene.model);
  return c;
}

// removes the frame files after `frame` (and any half-written .part file)
void removeFramesAfter(const fs::path& dir, int frame) {
  static const std::regex frameFile(R"((cloth|water)_(\d{4,})\.(obj|ply)(\.part)?)");
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && std::regex_match(name, m, frameFile) && (m[4].matched || std::stoll(m[2]) > frame))
      fs::remove(entry.path());
  }
}

// keeps the lines of stats.jsonl up to `frame` (a line that does not parse ends the kept part: a
// crash can leave half a line)
void truncateStats(const fs::path& dir, int frame) {
  const std::string path = (dir / "stats.jsonl").string();
  std::istringstream in(fs::exists(path) ? readTextFile(path) : std::string());
  std::string kept;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("frame") || !j["frame"].is_number_integer()) break;
    if (j["frame"].get<int>() > frame) break;
    kept += line + '\n';
  }
  writeTextFile(path, kept);
}

}  // namespace

int resumeCommand(const ResumeOptions& o) {
  const Clock::time_point wallStart = Clock::now();
  const fs::path dir(o.dir);
  nlohmann::ordered_json run = readRunJson(dir);
  Scene scene;
  const Checkpoint c = readMatchingCheckpoint(dir, scene);
  const int frames = o.frames >= 0 ? o.frames : run.value("frames", scene.output.frames);
  const int checkpointEvery = o.checkpointEvery >= 0 ? o.checkpointEvery : run.value("checkpointEvery", 0);
  if (c.info.frame >= frames) {
    std::printf("soak: %s is complete to frame %d; pass --frames N with N > %d to extend it\n", o.dir.c_str(),
                c.info.frame, c.info.frame);
    return kExitOk;
  }
  if (o.threads > 0) setThreadCount(o.threads);
  if (!o.quiet) std::fputs(busyMachineHint(threadCount()).c_str(), stderr);
  scene.state = c.state;
  removeFramesAfter(dir, c.info.frame);
  truncateStats(dir, c.info.frame);

  run["frames"] = frames;
  run["threads"] = threadCount();
  if (checkpointEvery > 0) run["checkpointEvery"] = checkpointEvery;
  run["resumes"].push_back(nlohmann::ordered_json{{"startTime", isoTimeNow()},
                                                 {"commandLine", joinCommandLine(o.commandLine)},
                                                 {"fromFrame", c.info.frame},
                                                 {"stepsIntoFrame", c.info.stepsIntoFrame}});
  RunRecord record{run, (dir / "run.json").string(), wallStart, run.value("wallSeconds", 0.0)};
  record.write("running", c.info.frame + 1, scene.state);

  JsonLinesWriter stats((dir / "stats.jsonl").string(), /*append=*/true);
  FrameLoop loop;
  loop.firstFrame = c.info.frame + 1;
  loop.lastFrame = frames;
  loop.stepsDone = c.info.stepsIntoFrame;
  loop.frameSoFar = c.info.frameSoFar;
  loop.checkpointEvery = checkpointEvery;
  loop.sceneHash = c.info.sceneHash;
  loop.quiet = o.quiet;
  const FrameLoopResult result = simulateFrames(scene, loop, dir, stats, record);
  if (result.exitCode != kExitOk) return result.exitCode;
  if (!o.quiet) printRunSummary(scene, o.dir, loop.firstFrame, frames, result);
  return kExitOk;
}

}  // namespace soak::cli
