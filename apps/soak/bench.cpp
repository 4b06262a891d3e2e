// `soak bench`: times the solver stages on the scenes of bench/benchmarks.json (bench/README.md).
// Each scene runs in its own process (this program re-executed) so its peak memory is its own.
#include "commands.hpp"
#include "progress.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>
#include <soak/threads.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace soak::cli {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr int kDefaultSteps = 20;
constexpr int kDefaultWarmup = 5;

// one scene to time
struct BenchJob {
  std::string name;
  std::string scene;                 // path of the scene file
  std::vector<std::string> overrides;
  int warmup = kDefaultWarmup;
  int steps = kDefaultSteps;
  bool fromManifest = false;
  bool wholeRun = false;             // steps: the scene's output.frames x stepsPerFrame, no warm-up
  json targets = json::object();     // targetMsPerStep, targetBytesPerParticle
};

std::string defaultManifest() {
  const fs::path inSource = fs::path(SOAK_SOURCE_DIR) / "bench" / "benchmarks.json";
  if (fs::exists(inSource)) return inSource.string();
  return "bench/benchmarks.json";
}

std::vector<BenchJob> readManifest(const std::string& path) {
  const json doc = json::parse(readTextFile(path), nullptr, false, true);
  if (doc.is_discarded()) throw Error(path + ": invalid JSON");
  if (!doc.contains("benchmarks") || !doc["benchmarks"].is_array())
    throw Error(path + ": at benchmarks: expected an array of {name, scene, warmup, steps}");
  const fs::path base = fs::path(path).parent_path();
  std::vector<BenchJob> jobs;
  for (size_t k = 0; k < doc["benchmarks"].size(); ++k) {
    const json& e = doc["benchmarks"][k];
    const std::string where = fmt::format("benchmarks.{}", k);
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("scene") ||
        !e["scene"].is_string())
      throw Error(path + ": at " + where + ": expected an object with string \"name\" and \"scene\"");
    BenchJob j;
    j.name = e["name"];
    j.scene = (base / e["scene"].get<std::string>()).lexically_normal().string();
    j.fromManifest = true;
    for (const char* key : {"warmup", "steps"}) {
      if (!e.contains(key)) continue;
      if (!e[key].is_number_integer() || e[key].get<int>() < (key[0] == 's' ? 1 : 0))
        throw Error(path + ": at " + where + "." + key + ": expected a non-negative integer (steps >= 1)");
      (key[0] == 's' ? j.steps : j.warmup) = e[key].get<int>();
    }
    if (e.contains("set")) {
      if (!e["set"].is_array()) throw Error(path + ": at " + where + ".set: expected an array of \"key=value\"");
      for (const json& s : e["set"]) j.overrides.push_back(s.get<std::string>());
    }
    for (const char* key : {"targetMsPerStep", "targetBytesPerParticle"})
      if (e.contains(key)) j.targets[key] = e[key];
    jobs.push_back(std::move(j));
  }
  return jobs;
}

std::vector<BenchJob> selectJobs(const BenchOptions& o) {
  const std::string manifestPath = o.manifest.empty() ? defaultManifest() : o.manifest;
  const bool needManifest = o.scenes.empty() || !o.manifest.empty() ||
                            std::any_of(o.scenes.begin(), o.scenes.end(), [](const std::string& s) {
                              return !fs::is_regular_file(s);
                            });
  const std::vector<BenchJob> manifest = needManifest ? readManifest(manifestPath) : std::vector<BenchJob>{};
  std::vector<BenchJob> jobs;
  if (o.scenes.empty()) jobs = manifest;
  for (const std::string& s : o.scenes) {
    const auto it = std::find_if(manifest.begin(), manifest.end(), [&](const BenchJob& j) { return j.name == s; });
    if (it != manifest.end() && !fs::is_regular_file(s)) {
      jobs.push_back(*it);
    } else if (fs::is_regular_file(s)) {
      BenchJob j;
      j.name = fs::path(s).stem().string();
      j.scene = s;
      jobs.push_back(j);
    } else {
      std::string names;
      for (const BenchJob& j : manifest) names += (names.empty() ? "" : ", ") + j.name;
      throw Error(s + ": not a scene file nor a benchmark of " + manifestPath + " (" + names + ")");
    }
  }
  for (BenchJob& j : jobs) {
    if (o.steps > 0) j.steps = o.steps;
    if (o.warmup >= 0) j.warmup = o.warmup;
    if (o.wholeRun) j.wholeRun = true, j.warmup = 0;  // steps: known once the scene is loaded
    j.overrides.insert(j.overrides.end(), o.overrides.begin(), o.overrides.end());
  }
  return jobs;
}

// a float as the shortest decimal that reads back to it (0.015, not 0.014999999664723873)
double decimal(float f) { return std::stod(fmt::format("{}", f)); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// peak resident memory of this process, bytes (Linux reports ru_maxrss in KiB)
uint64_t peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<uint64_t>(u.ru_maxrss) * 1024u;
}

// the job's warm-up steps, then its timed steps with their stats; throws when either diverges
std::vector<StepStats> timeSteps(const BenchJob& job, const Model& model, State& state, int steps, bool quiet) {
  const float dt = model.solver.dt;
  WorkspacePtr ws = makeWorkspace();
  if (!quiet) std::fprintf(stderr, "soak bench: %s: %d warm-up steps, %d timed steps%s\n", job.name.c_str(), job.warmup,
                           steps, job.wholeRun ? " (the whole run)" : "");
  for (int s = 0; s < job.warmup; ++s) {
    StepStats st;
    step(model, state, *ws, dt, st);
  }
  std::string bad = checkState(model, state);
  if (!bad.empty()) throw Error(job.scene + ": diverged during warm-up: " + bad);
  std::vector<StepStats> timed(static_cast<size_t>(steps));
  // a whole run takes minutes: progress on stderr (also from the child process, whose table is quiet)
  Progress progress(steps, job.wholeRun);
  for (int k = 0; k < steps; ++k) {
    step(model, state, *ws, dt, timed[static_cast<size_t>(k)]);
    progress.updateItems("steps", k + 1, steps);
  }
  progress.finish();
  bad = checkState(model, state);
  if (!bad.empty()) throw Error(job.scene + ": diverged while timed: " + bad);
  return timed;
}

// the median and mean over the timed steps of every stage (ms, msMean) and every stage part (parts,
// partsMean), by name
struct StageSummary {
  json ms = json::object(), msMean = json::object();
  json parts = json::object(), partsMean = json::object();  // StagePart, as the stages
};

StageSummary summarizeStages(const std::vector<StepStats>& timed) {
  // the median and mean over the timed steps of one time, under name in med and mean
  const auto summarize = [&](json& med, json& mean, const char* name, auto&& time) {
    std::vector<double> v;
    double sum = 0.0;
    for (const StepStats& st : timed) v.push_back(time(st.ms)), sum += v.back();
    med[name] = median(v);
    mean[name] = sum / static_cast<double>(v.size());
  };
  StageSummary out;
  const auto stage = [&](const char* name, double StageTimes::*field) {
    summarize(out.ms, out.msMean, name, [&](const StageTimes& t) { return t.*field; });
  };
  stage("emit", &StageTimes::emit);
  stage("predict", &StageTimes::predict);
  stage("neighbors", &StageTimes::neighbors);
  stage("water", &StageTimes::water);
  stage("cloth", &StageTimes::cloth);
  stage("coupling", &StageTimes::coupling);
  stage("colliders", &StageTimes::colliders);
  stage("velocities", &StageTimes::velocities);
  stage("wetting", &StageTimes::wetting);
  stage("garment", &StageTimes::garment);
  stage("total", &StageTimes::total);
  for (int k = 0; k < kStagePartCount; ++k)
    summarize(out.parts, out.partsMean, kStagePartNames[k], [&](const StageTimes& t) { return t.parts[k]; });
  return out;
}

// whether the job met its targets: a window of steps compares its median (robust to a slow step); a
// whole run its mean, as Table 2 of Shao 2017 gives "the average time cost of each simulation step"
void checkTargets(const BenchJob& job, double medianTotal, double meanTotal, json& r) {
  if (job.targets.contains("targetMsPerStep")) {
    r["targets"]["msPerStepBasis"] = job.wholeRun ? "mean" : "median";
    r["targets"]["msPerStepMet"] = (job.wholeRun ? meanTotal : medianTotal) <= job.targets["targetMsPerStep"].get<double>();
  }
  if (job.targets.contains("targetBytesPerParticle"))
    r["targets"]["bytesPerParticleMet"] = r["bytesPerParticle"].get<double>() <= job.targets["targetBytesPerParticle"].get<double>();
}

json runOne(const BenchJob& job, int threads, bool quiet) {
  Scene scene = loadScene(job.scene, job.overrides);
  if (threads > 0) setThreadCount(threads);
  if (!quiet) std::fputs(busyMachineHint(threadCount()).c_str(), stderr);
  const Model& model = scene.model;
  State& state = scene.state;
  const int steps = job.wholeRun ? scene.output.frames * scene.output.stepsPerFrame : job.steps;
  if (steps < 1)
    throw Error(job.scene + ": --whole-run needs at least one step (output.frames x output.stepsPerFrame is " +
                std::to_string(steps) + ")");
  const std::vector<StepStats> timed = timeSteps(job, model, state, steps, quiet);

  size_t water = 0;
  for (int32_t ph : state.particles.phase) water += isWater(ph) ? 1 : 0;
  const size_t particles = state.particles.size();
  const StageSummary st = summarizeStages(timed);
  uint64_t contacts = 0;
  for (const StepStats& t : timed) contacts += t.couplingContacts;
  const double meanTotal = st.msMean["total"].get<double>();
  const uint64_t peak = peakRssBytes();
  const double medianTotal = st.ms["total"].get<double>();
  json r = {{"name", job.name},
            {"scene", job.scene},
            {"overrides", job.overrides},
            {"threads", threadCount()},
            {"warmup", job.warmup},
            {"steps", steps},
            {"wholeRun", job.wholeRun},
            {"dt", decimal(model.solver.dt)},
            {"particles", {{"water", water}, {"cloth", model.numCloth}, {"total", particles}}},
            {"iterations",
             {{"fluid", model.solver.fluidIterations},
              {"fluidMax", model.solver.fluidMaxIterations},
              {"cloth", model.solver.clothIterations},
              {"coupling", model.solver.couplingIterations},
              {"substeps", model.solver.substeps}}},
            {"clothSolve",
             {{"smallSteps", model.solver.clothSubsteps},
              {"hierarchy", model.solver.clothHierarchy},
              {"pinPasses", model.solver.clothPinPasses},
              {"pinRings", model.solver.clothPinRings},
              {"globalStretch", model.solver.clothGlobalStretch}}},
            {"msPerStepMedian", st.ms},
            {"msPerStepMean", meanTotal},
            {"msPerStepMeanStages", st.msMean},
            {"msPerStepMedianParts", st.parts},
            {"msPerStepMeanParts", st.partsMean},
            {"nsPerParticleStep", particles > 0 ? medianTotal * 1e6 / static_cast<double>(particles) : 0.0},
            {"couplingContactsPerStep", timed.empty() ? 0.0 : static_cast<double>(contacts) / timed.size()},
            {"peakRssBytes", peak},
            {"bytesPerParticle", particles > 0 ? static_cast<double>(peak) / static_cast<double>(particles) : 0.0},
            {"simulatedSeconds", state.time},
            {"stateHash", fmt::format("{:016x}", stateHash(state))},
            {"targets", job.targets}};
  checkTargets(job, medianTotal, meanTotal, r);
  return r;
}

// runs `soak bench --scene X` for one job in a fresh process and reads back its JSON
json runInChild(const BenchJob& job, const BenchOptions& o, int index) {
  const fs::path out = fs::temp_directory_path() / fmt::format("soak_bench_{}_{}.json", ::getpid(), index);
  std::vector<std::string> args = {"soak", "bench", "--quiet", "--in-process", "--json", out.string()};
  if (job.wholeRun)
    args.push_back("--whole-run");
  else
    args.insert(args.end(), {"--steps", std::to_string(job.steps), "--warmup", std::to_string(job.warmup)});
  if (job.fromManifest) {
    args.insert(args.end(), {"--manifest", o.manifest.empty() ? defaultManifest() : o.manifest, "--scene", job.name});
  } else {
    args.insert(args.end(), {"--scene", job.scene});
  }
  if (o.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.threads)});
  for (const std::string& s : o.overrides) args.insert(args.end(), {"--set", s});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0)
    throw Error("soak bench: cannot start /proc/self/exe for " + job.name);
  int status = 0;
  waitpid(pid, &status, 0);
  // a child that ran but failed still wrote its error into the JSON
  std::error_code ec;
  if (fs::exists(out, ec)) {
    const json doc = json::parse(readTextFile(out.string()), nullptr, false);
    fs::remove(out, ec);
    if (!doc.is_discarded() && doc.contains("results") && doc["results"].size() == 1) return doc["results"][0];
  }
  const std::string why = WIFEXITED(status) ? fmt::format("exit code {}", WEXITSTATUS(status))
                                            : fmt::format("signal {}", WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return {{"name", job.name}, {"scene", job.scene}, {"error", "the benchmark process failed (" + why + ")"}};
}

std::string mib(double bytes) { return fmt::format("{:.1f}", bytes / (1024.0 * 1024.0)); }

void printTable(const std::vector<json>& results) {
  std::printf("%-18s %9s %7s %11s %9s %8s %8s %8s %9s %8s %8s %8s %8s %9s %9s %6s  %s\n", "scene", "water",
              "cloth", "it f/c/cp/s", "neighbors", "water", "cloth", "coupling", "colliders", "wetting", "garment",
              "total", "mean", "ns/p/step", "peak MiB", "B/p", "target");
  for (const json& r : results) {
    if (r.contains("error")) {
      std::printf("%-18s %s\n", r["name"].get<std::string>().c_str(), r["error"].get<std::string>().c_str());
      continue;
    }
    const bool whole = r.value("wholeRun", false);
    const json& ms = r[whole ? "msPerStepMeanStages" : "msPerStepMedian"];
    const json& it = r["iterations"];
    std::string target;
    if (r["targets"].contains("msPerStepMet"))
      target += fmt::format("{} {} ms/step{} ", r["targets"]["msPerStepMet"].get<bool>() ? "met" : "MISSED",
                            r["targets"]["targetMsPerStep"].get<double>(), whole ? " (mean)" : "");
    if (r["targets"].contains("bytesPerParticleMet"))
      target += fmt::format("{} {} B/p", r["targets"]["bytesPerParticleMet"].get<bool>() ? "met" : "MISSED",
                            r["targets"]["targetBytesPerParticle"].get<double>());
    std::printf("%-18s %9llu %7llu %11s %9.2f %8.2f %8.2f %8.2f %9.2f %8.2f %8.2f %8.2f %8.2f %9.1f %9s %6.0f  %s\n",
                r["name"].get<std::string>().c_str(), r["particles"]["water"].get<unsigned long long>(),
                r["particles"]["cloth"].get<unsigned long long>(),
                fmt::format("{}/{}/{}/{}", it["fluid"].get<int>(), it["cloth"].get<int>(), it["coupling"].get<int>(),
                            it["substeps"].get<int>())
                    .c_str(),
                ms["neighbors"].get<double>(), ms["water"].get<double>(), ms["cloth"].get<double>(),
                ms["coupling"].get<double>(), ms["colliders"].get<double>(), ms["wetting"].get<double>(),
                ms["garment"].get<double>(), ms["total"].get<double>(),
                r["msPerStepMean"].get<double>(), r["nsPerParticleStep"].get<double>(),
                mib(r["peakRssBytes"].get<double>()).c_str(), r["bytesPerParticle"].get<double>(), target.c_str());
  }
  const bool anyWhole = std::any_of(results.begin(), results.end(), [](const json& r) { return r.value("wholeRun", false); });
  std::printf("(ms per step: %s; total includes emit, predict and velocities; peak: ru_maxrss of the process that "
              "ran the scene)\n",
              anyWhole ? "mean over every step of the run (--whole-run)"
                       : "median over the timed steps");
}

// --stages: the parts of the stages (StagePart), a column each headed by the part's name in its stage
void printParts(const std::vector<json>& results) {
  std::vector<std::string> heads;
  for (const char* name : kStagePartNames) heads.push_back(std::string(name).substr(std::string(name).find('.') + 1));
  const auto width = [&](int k) { return std::max<int>(8, static_cast<int>(heads[static_cast<size_t>(k)].size())); };
  std::printf("\n%-18s", "parts (ms)");
  for (int k = 0; k < kStagePartCount; ++k) std::printf(" %*s", width(k), heads[static_cast<size_t>(k)].c_str());
  std::printf("\n");
  for (const json& r : results) {
    if (r.contains("error") || !r.contains("msPerStepMedianParts")) continue;
    const json& parts = r[r.value("wholeRun", false) ? "msPerStepMeanParts" : "msPerStepMedianParts"];
    std::printf("%-18s", r["name"].get<std::string>().c_str());
    for (int k = 0; k < kStagePartCount; ++k) std::printf(" %*.2f", width(k), parts[kStagePartNames[k]].get<double>());
    std::printf("\n");
  }
  std::printf("(neighbors: grid, lists; cloth: solve (with the tethers), selfCollision; coupling: search (with Eq. 22's "
              "stiffness), passes (the rigid one too); velocities: xsph; wetting: its seven stages, once a step; "
              "garment: assemble (forces, rows, system), cg (with the contact rounds), integrate (with the "
              "collider and edge contact), selfContact, drops (wet by contact); each within its stage's time "
              "above)\n");
}

}  // namespace

int benchCommand(const BenchOptions& o) {
  const std::vector<BenchJob> jobs = selectJobs(o);
  if (jobs.empty()) throw Error("soak bench: no scenes to run");
  const bool separate = !o.inProcess && jobs.size() > 1;
  std::vector<json> results;
  bool failed = false;
  for (size_t k = 0; k < jobs.size(); ++k) {
    json r;
    if (separate) {
      if (!o.quiet) std::fprintf(stderr, "soak bench: [%zu/%zu] %s\n", k + 1, jobs.size(), jobs[k].name.c_str());
      r = runInChild(jobs[k], o, static_cast<int>(k));
    } else {
      try {
        r = runOne(jobs[k], o.threads, o.quiet);
      } catch (const Error& e) {
        std::fprintf(stderr, "soak: error: %s\n", e.what());
        r = {{"name", jobs[k].name}, {"scene", jobs[k].scene}, {"error", e.what()}};
      }
    }
    failed |= r.contains("error");
    results.push_back(std::move(r));
  }
  if (!o.quiet) printTable(results);
  if (!o.quiet && o.stages) printParts(results);
  if (!o.json.empty()) {
    const json doc = {{"soak", kVersion}, {"results", results}};
    writeTextFile(o.json, doc.dump(2) + "\n");
  }
  return failed ? kExitError : kExitOk;
}

}  // namespace soak::cli
