// a grid of labelled pictures as one PNG, made by ffmpeg (render.hpp: writeContactSheet)
#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/render.hpp>

#include "render/process.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <unistd.h>

namespace soak {

namespace {

namespace fs = std::filesystem;

constexpr int kFontSize = 14, kLineHeight = 18, kMargin = 6;

// tile i's chain from input i: the picture (or white), taller by the caption band, and one drawtext
// per line (read from a file in the work folder, so no caption text is parsed as filter syntax)
std::string tileChain(size_t i, int band, int lines) {
  std::string chain = fmt::format("[{}:v]pad=iw:ih+{}:0:0:color=white", i, band);
  for (int l = 0; l < lines; ++l)
    chain += fmt::format(",drawtext=textfile=c{}_{}.txt:expansion=none:fontsize={}:fontcolor=black:x={}:y=h-{}", i, l,
                         kFontSize, kMargin, band - kMargin - l * kLineHeight);
  return chain + fmt::format("[t{}]", i);
}

}  // namespace

void writeContactSheet(const std::vector<ContactTile>& tiles, int columns, int width, int height,
                       const std::string& outPng, double timeoutSeconds) {
  if (tiles.empty() || columns < 1) throw Error(outPng + ": a contact sheet needs at least one tile and one column");
  const std::string ffmpeg = requireExecutable("ffmpeg", "ffmpeg");
  for (const ContactTile& t : tiles)
    if (!t.image.empty() && pngSize(t.image) != std::pair{width, height})
      throw Error(fmt::format("{}: expected a {} x {} picture for the contact sheet {}", t.image, width, height, outPng));
  size_t lines = 1;
  for (const ContactTile& t : tiles) lines = std::max(lines, t.caption.size());
  const int band = int(lines) * kLineHeight + 2 * kMargin;
  const fs::path work = fs::path(outPng).parent_path() / fmt::format(".contact_sheet_{}", ::getpid());
  fs::create_directories(work);
  const int rows = int((tiles.size() + size_t(columns) - 1) / size_t(columns));
  const size_t cells = size_t(rows) * size_t(columns);
  // inputs: the pictures, then one white picture for every blank tile and empty cell
  std::vector<std::string> args = {ffmpeg, "-hide_banner", "-loglevel", "error", "-y"};
  std::string graph, stack;
  const std::string blank = fmt::format("color=c=white:s={}x{}", width, height);
  for (size_t i = 0; i < cells; ++i) {
    const ContactTile empty;
    const ContactTile& t = i < tiles.size() ? tiles[i] : empty;
    if (t.image.empty()) args.insert(args.end(), {"-f", "lavfi", "-i", blank});
    else args.insert(args.end(), {"-i", fs::absolute(t.image).string()});
    for (size_t l = 0; l < t.caption.size(); ++l)
      writeTextFile((work / fmt::format("c{}_{}.txt", i, l)).string(), t.caption[l]);
    graph += tileChain(i, band, int(t.caption.size()));
    stack += fmt::format("[t{}]", i);
    if (i + 1 < cells) graph += ";";
  }
  if (cells > 1) graph += fmt::format(";{}xstack=inputs={}:grid={}x{}[out]", stack, cells, columns, rows);
  const std::string out = fs::absolute(outPng).string();
  args.insert(args.end(), {"-filter_complex", graph, "-map", cells == 1 ? "[t0]" : "[out]", "-frames:v", "1", out});
  const std::string log = (work / "ffmpeg.log").string();
  const ProcessResult r = runProcess(args, work.string(), log, timeoutSeconds);
  const std::string tail = tailOfFile(log, 8);
  std::error_code ec;
  fs::remove_all(work, ec);
  if (!r.ok()) throw Error(fmt::format("{}: ffmpeg failed ({}): {}", outPng, r.describe(), tail));
}

}  // namespace soak
