// soak sweep --slurm: the sweep as an sbatch job array, one task per variant (docs/sweeps.md)
#pragma once
#include "commands.hpp"

#include <soak/sweep.hpp>

#include <csignal>
#include <string>
#include <vector>

namespace soak::cli {

// the job array script for the variants `todo` (indices into spec.variants): each task runs
// `soak sweep SWEEP -o DIR --only $SLURM_ARRAY_TASK_ID` with this program, all paths absolute
std::string sbatchScript(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo);

// writes DIR/sweep.sbatch and, unless o.dryRun, submits it with sbatch; returns the job id ("" when
// nothing was submitted). Throws soak::Error when sbatch fails, with what it said
std::string submitSweep(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo);

// polls squeue every 5 s until the job has left the queue (true), or `stop` is set by a signal (false)
bool waitForJob(const std::string& job, const volatile std::sig_atomic_t& stop);

// "" when `value` can go on an #SBATCH line (1 to 128 printable characters, no space or quote),
// else what is wrong with it
std::string sbatchValueProblem(const std::string& value);

}  // namespace soak::cli
