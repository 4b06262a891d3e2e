// soak sweep --slurm (sweep_slurm.hpp)
#include "sweep_slurm.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;

std::string absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

// "0-3" or "0,2,5-7": the array's task ids
std::string arraySpec(const std::vector<size_t>& todo) {
  std::vector<std::string> parts;
  for (size_t i = 0; i < todo.size();) {
    size_t j = i;
    while (j + 1 < todo.size() && todo[j + 1] == todo[j] + 1) ++j;
    parts.push_back(j == i ? std::to_string(todo[i]) : fmt::format("{}-{}", todo[i], todo[j]));
    i = j + 1;
  }
  return fmt::format("{}", fmt::join(parts, ","));
}

// runs a shell command line, returns its exit code and what it printed (stdout and stderr)
int capture(const std::string& command, std::string& output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) throw Error("soak sweep: cannot run " + command);
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::string sbatchValueProblem(const std::string& value) {
  if (value.empty() || value.size() > 128) return "expected 1 to 128 characters";
  for (char c : value)
    if (c <= ' ' || c > '~' || c == '\'' || c == '"' || c == '\\')
      return fmt::format("expected no space, quote, backslash or control character, got '{}'", value);
  return {};
}

std::string sbatchScript(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo) {
  const std::string dir = absolute(o.outDir);
  std::string s = "#!/bin/bash\n# soak sweep --slurm: one array task per variant still to run (docs/sweeps.md)\n";
  s += "#SBATCH --job-name=soak-sweep\n";
  s += fmt::format("#SBATCH --array={}\n", arraySpec(todo));
  s += fmt::format("#SBATCH --cpus-per-task={}\n", o.cpusPerTask);
  if (!o.time.empty()) s += fmt::format("#SBATCH --time={}\n", o.time);
  if (!o.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", o.partition);
  s += "#SBATCH --output=" + joinCommandLine({dir + "/slurm-%A_%a.out"}) + "\n";
  std::vector<std::string> run = {fs::read_symlink("/proc/self/exe").string(), "sweep", absolute(spec.file), "-o", dir};
  if (spec.frames >= 0) run.insert(run.end(), {"--frames", std::to_string(spec.frames)});
  s += "exec " + joinCommandLine(run) + " --only \"$SLURM_ARRAY_TASK_ID\" --threads \"${SLURM_CPUS_PER_TASK:-" +
       std::to_string(o.cpusPerTask) + "}\" -q\n";
  return s;
}

std::string submitSweep(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo) {
  if (todo.empty()) {
    if (!o.quiet) std::printf("soak sweep: every variant is complete; nothing to submit\n");
    return {};
  }
  const std::string script = (fs::path(o.outDir) / "sweep.sbatch").string();
  writeTextFile(script, sbatchScript(spec, o, todo));
  if (o.dryRun) {
    std::printf("soak sweep: wrote %s (%zu tasks); submit it with: sbatch %s\n", script.c_str(), todo.size(),
                joinCommandLine({script}).c_str());
    return {};
  }
  std::string out;
  const int code = capture("sbatch --parsable " + joinCommandLine({script}), out);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  if (code != 0)
    throw Error(fmt::format("soak sweep: sbatch {} failed (exit code {}): {}{}", script, code, out,
                            code == 127 ? " (install Slurm's client, Debian's slurm-client, or run without --slurm)" : ""));
  if (o.wait)
    std::printf("soak sweep: submitted job %s, %zu tasks (%s); waiting for it\n", out.c_str(), todo.size(),
                arraySpec(todo).c_str());
  else
    std::printf("soak sweep: submitted job %s, %zu tasks (%s); when it is done: %s --collect\n", out.c_str(),
                todo.size(), arraySpec(todo).c_str(), joinCommandLine({"soak", "sweep", spec.file, "-o", o.outDir}).c_str());
  std::fflush(stdout);
  return out;
}

bool waitForJob(const std::string& job, const volatile std::sig_atomic_t& stop) {
  while (stop == 0) {
    std::string out;
    // squeue fails once the job has left its records: gone as well
    if (capture("squeue --noheader --jobs=" + joinCommandLine({job}), out) != 0 ||
        out.find_first_not_of(" \t\r\n") == std::string::npos)
      return true;
    for (int i = 0; i < 20 && stop == 0; ++i) ::usleep(250000);  // 5 s, a signal ends it sooner
  }
  return false;
}

}  // namespace soak::cli
