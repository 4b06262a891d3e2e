// soak sweep's summary table (sweep_summary.hpp)
#include "sweep_summary.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/run_summary.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// what went wrong, from a variant's log: the first non-empty line of its last attempt (after the last
// resume mark); soak run -q prints nothing but its errors. "" when there is none
std::string logError(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return {};
  std::istringstream in(readTextFile(path));
  std::string first;
  for (std::string line; std::getline(in, line);) {
    if (line == kResumeMark) first.clear();
    else if (first.empty() && line.find_first_not_of(" \t\r") != std::string::npos) first = line;
  }
  return first;
}

struct Row {
  std::string status;  // complete, failed, diverged, interrupted, running, pending
  std::string error;
  RunSummary run;
};

Row measure(const SweepSpec& spec, const SweepVariant& v, const std::string& dir) {
  const std::string folder = (fs::path(dir) / v.folder).string();
  Row row;
  try {
    row.run = summarizeRun(folder);
  } catch (const Error& e) {
    return {"failed", e.what(), {}};
  }
  const std::string& s = row.run.status;
  std::error_code ec;
  if (runComplete(row.run, spec.frames)) row.status = "complete";
  else if (s == "ok") row.status = "pending";  // complete with fewer frames than asked now: runs again
  else if (s == "interrupted" || s == "diverged" || s == "running") row.status = s;
  else if (s == "missing" && !fs::exists(folder + ".log", ec)) row.status = "pending";
  else row.status = "failed";
  if (row.status != "complete" && row.status != "pending" && row.status != "running") row.error = logError(folder + ".log");
  return row;
}

// a number for the tables: null (JSON) or empty (CSV) when not measured
json number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q(1, '"');
  for (char c : s) {
    if (c == '"') q.push_back('"');  // a quote doubled
    q.push_back(c == '\n' || c == '\r' ? ' ' : c);
  }
  q.push_back('"');
  return q;
}

std::string csvNumber(const json& x) { return x.is_null() ? std::string() : x.dump(); }

json rowJson(const SweepVariant& v, const Row& r) {
  json params = json::object();
  for (const auto& [key, value] : v.params) params[key] = json::parse(value);
  return {{"variant", v.folder},
          {"params", params},
          {"status", r.status},
          {"error", r.error},
          {"framesWritten", r.run.framesWritten},
          {"frame", r.run.frame},
          {"msPerStep", number(r.run.msPerStep)},
          {"heldWaterKg", number(r.run.heldWaterKg)},
          {"wetAreaFraction", number(r.run.wetAreaFraction)},
          {"maxClothStrain", number(r.run.maxClothStrain)}};
}

std::string csvTable(const SweepSpec& spec, const json& rows) {
  std::string out = "variant";
  for (const std::string& k : spec.keys) out += fmt::format(",{}", csvField(k));
  out += ",status,error,framesWritten,frame,msPerStep,heldWaterKg,wetAreaFraction,maxClothStrain\n";
  for (const json& r : rows) {
    out += r["variant"].get<std::string>();
    for (const auto& [key, value] : r["params"].items())
      out += fmt::format(",{}", csvField(value.is_string() ? value.get<std::string>() : value.dump()));
    out += fmt::format(",{},{},{},{},{},{},{},{}\n", r["status"].get<std::string>(), csvField(r["error"].get<std::string>()),
                       r["framesWritten"].dump(), r["frame"].dump(), csvNumber(r["msPerStep"]), csvNumber(r["heldWaterKg"]),
                       csvNumber(r["wetAreaFraction"]), csvNumber(r["maxClothStrain"]));
  }
  return out;
}

}  // namespace

bool runComplete(const RunSummary& s, int frames) {
  return s.status == "ok" && (frames < 0 || s.framesWritten == frames + 1);
}

SweepTotals writeSweepSummary(const SweepSpec& spec, const std::string& dir, bool quiet) {
  SweepTotals t;
  json rows = json::array();
  for (const SweepVariant& v : spec.variants) {
    const Row r = measure(spec, v, dir);
    if (r.status == "complete") ++t.complete;
    else if (r.status == "interrupted") ++t.interrupted;
    else if (r.status == "pending" || r.status == "running") ++t.pending;
    else ++t.failed;
    rows.push_back(rowJson(v, r));
  }
  const json doc = {{"sweep", fs::absolute(spec.file).lexically_normal().string()},
                    {"scene", spec.scene},
                    {"keys", spec.keys},
                    {"variants", rows}};
  writeTextFile((fs::path(dir) / "summary.json").string(), doc.dump(2) + "\n");
  writeTextFile((fs::path(dir) / "summary.csv").string(), csvTable(spec, rows));
  if (!quiet)
    std::printf("soak sweep: %d complete, %d failed, %d interrupted, %d pending; summary in %s/summary.csv and summary.json\n",
                t.complete, t.failed, t.interrupted, t.pending, dir.c_str());
  return t;
}

}  // namespace soak::cli
