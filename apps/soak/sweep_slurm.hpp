// soak sweep --slurm: the sweep as an sbatch job array, one task per variant (docs/sweeps.md)
#pragma once
#include "commands.hpp"

#include <soak/sweep.hpp>

#include <string>
#include <vector>

namespace soak::cli {

// the job array script for the variants `todo` (indices into spec.variants): each task runs
// `soak sweep SWEEP -o DIR --only $SLURM_ARRAY_TASK_ID` with this program, all paths absolute
std::string sbatchScript(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo);

// writes DIR/sweep.sbatch and, unless o.dryRun, submits it with sbatch; returns the exit code
int submitSweep(const SweepSpec& spec, const SweepOptions& o, const std::vector<size_t>& todo);

// "" when `value` can go on an #SBATCH line (1 to 128 printable characters, no space or quote),
// else what is wrong with it
std::string sbatchValueProblem(const std::string& value);

}  // namespace soak::cli
