// `soak sweep`: every variant of a SWEEP.json run by `soak run` in its own process, N at a time,
// into DIR/vNNN; variants already complete are skipped, interrupted ones resumed from their
// checkpoint; then the summary table (sweep_summary.cpp). docs/sweeps.md
#include "commands.hpp"
#include "sweep_slurm.hpp"
#include "stop_signals.hpp"
#include "sweep_summary.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/run_summary.hpp>
#include <soak/sweep.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace soak::cli {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// the expanded sweep as DIR/sweep.json: what a later `soak sweep` on DIR must match to resume it
json sweepRecord(const SweepSpec& spec) {
  json variants = json::array();
  for (const SweepVariant& v : spec.variants) {
    json params = json::object();
    for (const auto& [key, value] : v.params) params[key] = json::parse(value);
    variants.push_back({{"folder", v.folder}, {"params", params}});
  }
  return {{"scene", fs::absolute(spec.scene).lexically_normal().string()}, {"set", spec.common},
          {"frames", spec.frames}, {"keys", spec.keys}, {"variants", variants}};
}

// writes DIR/sweep.json, or checks that the one there is this sweep's (the frames may change: a
// sweep is extended by asking for more) and, with `rewrite`, writes it again with the frames asked
// for now (an array task only checks: its siblings read the same file)
void claimFolder(const SweepSpec& spec, const std::string& dir, bool rewrite) {
  const std::string path = (fs::path(dir) / "sweep.json").string();
  const json mine = sweepRecord(spec);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the sweep's folder: " + ec.message());
  if (fs::exists(path, ec)) {
    json there = json::parse(readTextFile(path), nullptr, false);
    if (there.is_object()) there["frames"] = spec.frames;
    if (there != mine)
      throw Error(fmt::format("{}: holds another sweep (its sweep.json differs from {}'s variants); give another "
                              "-o, or remove the folder",
                              dir, spec.file));
    if (!rewrite) return;
  }
  writeTextFile(path, mine.dump(2) + "\n");
}

// adds a line to a variant's log (created when missing)
void appendLine(const std::string& path, const std::string& line) {
  std::ofstream out(path, std::ios::app);
  out << line << '\n';
  if (!out) throw Error(path + ": cannot write the variant's log");
}

// DIR/vNNN.lock is held (flock) by the sweep process whose child runs variant NNN: another sweep on
// the same folder (a second terminal, an array submitted again) leaves a held variant alone, and a
// variant whose sweep died (the lock goes with the process) is taken up again. The descriptor, or -1
// when another process holds it
int tryLock(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(fmt::format("{}: cannot open the variant's lock: {}", path, std::strerror(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return fd;
  ::close(fd);
  return -1;
}

// what a variant's folder needs: nothing (complete), nothing now (another sweep runs it), a resume
// from its checkpoint, or a (new) run
enum class Need { Nothing, Busy, Resume, Run };

Need needOf(const std::string& folder, int frames) {
  std::error_code ec;
  if (!fs::exists(folder, ec)) return Need::Run;
  const int lock = tryLock(folder + ".lock");
  if (lock < 0) return Need::Busy;
  ::close(lock);
  const RunSummary s = runStatus(folder);
  if (runComplete(s, frames)) return Need::Nothing;
  // interrupted, or killed without a word (its run.json still says running): on from its checkpoint
  if ((s.status == "interrupted" || s.status == "running") && fs::exists(fs::path(folder) / "checkpoint.soak", ec))
    return Need::Resume;
  return Need::Run;
}

std::vector<std::string> childArgs(const SweepSpec& spec, const SweepVariant& v, const std::string& folder, Need need,
                                   int threads) {
  std::vector<std::string> a = {"soak"};
  if (need == Need::Resume) {
    a.insert(a.end(), {"resume", folder});
    if (spec.frames >= 0) a.insert(a.end(), {"--frames", std::to_string(spec.frames)});
  } else {
    a.insert(a.end(), {"run", spec.scene, "-o", folder, "--overwrite"});
    if (spec.frames >= 0) a.insert(a.end(), {"--frames", std::to_string(spec.frames)});
    for (const std::string& s : spec.common) a.insert(a.end(), {"--set", s});
    for (const std::string& s : v.overrides()) a.insert(a.end(), {"--set", s});
    a.insert(a.end(), {"--checkpoint-every", "10"});
  }
  a.insert(a.end(), {"--threads", std::to_string(threads), "-q"});
  return a;
}

// starts this program with args, stdin from /dev/null, stdout and stderr to logPath (appended to
// with `append`, a resume, else replaced), in a process group of its own (a Ctrl-C reaches the sweep
// only, which passes it on once)
pid_t spawnLogged(const std::vector<std::string>& args, const std::string& logPath, bool append) {
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, logPath.c_str(), O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC), 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& s : copy) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, "/proc/self/exe", &fa, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw Error(fmt::format("soak sweep: cannot start /proc/self/exe for {}", logPath));
  return pid;
}

struct Job {
  size_t variant;
  Need need;
};

struct Running {
  size_t variant;
  std::chrono::steady_clock::time_point start;
  int lock;  // its DIR/vNNN.lock, held until it ends
};

// runs the jobs `jobs` at a time; prints a line as each ends; stops starting new ones on a signal
// (the running ones get it too and write their checkpoints)
void runJobs(const SweepSpec& spec, const std::string& dir, const std::vector<Job>& jobs, int parallel, int threads,
             bool quiet) {
  std::map<pid_t, Running> running;
  size_t next = 0, done = 0;
  bool forwarded = false;
  while (next < jobs.size() || !running.empty()) {
    while (gStopSignal == 0 && next < jobs.size() && running.size() < size_t(parallel)) {
      const Job& j = jobs[next++];
      const SweepVariant& v = spec.variants[j.variant];
      const std::string folder = (fs::path(dir) / v.folder).string();
      const int lock = tryLock(folder + ".lock");
      if (lock < 0) {  // taken since needOf looked
        if (!quiet) std::printf("soak sweep: %s is being run by another sweep; left alone\n", v.folder.c_str());
        continue;
      }
      if (j.need == Need::Resume) appendLine(folder + ".log", kResumeMark);
      const pid_t pid = spawnLogged(childArgs(spec, v, folder, j.need, threads), folder + ".log", j.need == Need::Resume);
      running[pid] = {j.variant, std::chrono::steady_clock::now(), lock};
    }
    if (running.empty()) break;
    if (gStopSignal != 0 && !forwarded) {  // once: a second signal would stop them without a checkpoint
      for (const auto& r : running) kill(r.first, int(gStopSignal));
      forwarded = true;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;  // a signal: passed on at the top of the loop
      throw Error(fmt::format("soak sweep: waiting for the variants failed: {}", std::strerror(errno)));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const SweepVariant& v = spec.variants[it->second.variant];
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.start).count();
    ::close(it->second.lock);
    running.erase(it);
    ++done;
    if (!quiet) {
      const std::string how = WIFEXITED(status) ? (WEXITSTATUS(status) == 0 ? "done" : fmt::format("exit {}", WEXITSTATUS(status)))
                                                : fmt::format("signal {}", WTERMSIG(status));
      std::printf("soak sweep: [%zu/%zu] %s (%s): %s in %.1f s\n", done, jobs.size(), v.folder.c_str(), v.label().c_str(),
                  how.c_str(), s);
      std::fflush(stdout);
    }
  }
}

// the variants to run (one with --only; none with --collect), each with what it needs
std::vector<Job> jobsToRun(const SweepSpec& spec, const SweepOptions& o) {
  std::vector<Job> jobs;
  for (size_t i = 0; i < spec.variants.size(); ++i) {
    if (o.collect || (o.only >= 0 && size_t(o.only) != i)) continue;
    const Need need = needOf((fs::path(o.outDir) / spec.variants[i].folder).string(), spec.frames);
    if (need == Need::Busy && !o.quiet)
      std::printf("soak sweep: %s is being run by another sweep; left alone\n", spec.variants[i].folder.c_str());
    if (need == Need::Resume || need == Need::Run) jobs.push_back({i, need});
  }
  return jobs;
}

// runs the jobs here, N at a time, passing SIGINT / SIGTERM on to them
void runHere(const SweepSpec& spec, const SweepOptions& o, const std::vector<Job>& jobs) {
  const int cores = o.threads > 0 ? o.threads : std::max(1, int(std::thread::hardware_concurrency()));
  const int parallel = std::max(1, std::min({o.jobs, int(std::max<size_t>(jobs.size(), 1)), cores}));
  const int threads = std::max(1, cores / parallel);
  if (!o.quiet)
    std::printf("soak sweep: %zu to run (%zu complete), %d at a time with %d threads each, into %s\n", jobs.size(),
                (o.only >= 0 ? size_t(1) : spec.variants.size()) - jobs.size(), parallel, threads, o.outDir.c_str());
  if (jobs.empty()) return;
  const StopSignals guard;
  runJobs(spec, o.outDir, jobs, parallel, threads, o.quiet);
}

}  // namespace

int sweepCommand(const SweepOptions& o) {
  SweepSpec spec = loadSweep(o.sweep);
  if (o.frames >= 0) spec.frames = o.frames;
  if (o.only >= int(spec.variants.size()))
    throw Error(fmt::format("soak sweep: --only {}: the sweep has variants 0 to {}", o.only, spec.variants.size() - 1));
  if (!o.collect) {
    if (!o.quiet) std::printf("soak sweep: checking %s of %s\n", o.only >= 0 ? spec.variants[size_t(o.only)].folder.c_str()
                                                                     : fmt::format("{} variants", spec.variants.size()).c_str(),
                              spec.scene.c_str());
    checkSweepVariants(spec, o.only);
  }
  if (o.dryRun && !o.slurm) {
    for (const SweepVariant& v : spec.variants) std::printf("%s  %s\n", v.folder.c_str(), v.label().c_str());
    return kExitOk;
  }
  claimFolder(spec, o.outDir, o.only < 0);
  const std::vector<Job> jobs = jobsToRun(spec, o);
  if (o.slurm) {
    std::vector<size_t> todo;
    for (const Job& j : jobs) todo.push_back(j.variant);
    const std::string job = submitSweep(spec, o, todo);
    if (!o.wait || job.empty()) return kExitOk;
    const StopSignals guard;
    if (!waitForJob(job, gStopSignal)) {  // the job goes on: --collect later
      std::printf("soak sweep: stopped waiting; job %s goes on (soak sweep ... --collect when it is done)\n", job.c_str());
      return 128 + int(gStopSignal);
    }
  } else if (!o.collect) {
    runHere(spec, o, jobs);
  }
  const int stopped = gStopSignal != 0 ? 128 + int(gStopSignal) : 0;
  if (o.only >= 0) {  // one task of an array: its own variant decides; the summary is --collect's
    if (stopped != 0) return stopped;
    return needOf((fs::path(o.outDir) / spec.variants[size_t(o.only)].folder).string(), spec.frames) == Need::Nothing
               ? kExitOk
               : kExitError;
  }
  const SweepTotals totals = writeSweepSummary(spec, o.outDir, o.quiet);
  if (stopped != 0) return stopped;
  if (o.sheet && totals.complete > 0) {
    const std::string sheet = writeSweepSheet(spec, o.outDir, o.quiet);
    if (!o.quiet) std::printf("soak sweep: contact sheet %s\n", sheet.c_str());
  }
  return totals.complete == int(spec.variants.size()) ? kExitOk : kExitError;
}

}  // namespace soak::cli
