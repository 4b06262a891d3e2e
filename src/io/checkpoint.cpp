// checkpoint files (include/soak/checkpoint.hpp): a header (magic, format, byte order, the writer's
// version, the scene's hash, the frame position and the frame's statistics so far), the State field
// by field (arrays as a count and their raw little-endian elements), then the State's hash and an end mark
#include <soak/checkpoint.hpp>
#include <soak/error.hpp>
#include <soak/step.hpp>

#include "io/file.hpp"

#include <fmt/format.h>

#include <algorithm>

#include <bit>
#include <cstring>
#include <filesystem>
#include <type_traits>

namespace soak {

namespace {

constexpr char kMagic[8] = {'S', 'O', 'A', 'K', 'C', 'K', 'P', 'T'};
constexpr char kEndMark[8] = {'S', 'O', 'A', 'K', 'E', 'N', 'D', '.'};
constexpr uint32_t kByteOrderMark = 0x01020304u;
constexpr size_t kMaxVersionLength = 256;

static_assert(std::endian::native == std::endian::little, "checkpoints store little-endian values as they are in memory");
static_assert(std::is_trivially_copyable_v<FrameStats>, "the frame's statistics are stored as raw bytes");

class Writer {
 public:
  explicit Writer(std::ofstream& out) : out_(out) {}
  void bytes(const void* p, size_t n) { out_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n)); }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof v);
  }
  template <class T>
  void array(const std::vector<T>& v) {
    value(uint64_t{v.size()});
    bytes(v.data(), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value(uint64_t{s.size()});
    bytes(s.data(), s.size());
  }

 private:
  std::ofstream& out_;
};

// reads from the whole file in memory; every read is checked against what is left, so a truncated or
// corrupt file ends in an error naming the file and the field, never in a huge allocation
class Reader {
 public:
  // `data` must outlive the reader
  Reader(const std::string& path, const std::string& data) : path_(path), data_(data) {}
  void bytes(void* p, size_t n, const char* what) {
    if (n > data_.size() - pos_)
      throw Error(fmt::format("{}: truncated checkpoint: {} needs {} bytes at offset {}, the file has {} left", path_,
                              what, n, pos_, data_.size() - pos_));
    std::memcpy(p, data_.data() + pos_, n);
    pos_ += n;
  }
  template <class T>
  T value(const char* what) {
    T v;
    bytes(&v, sizeof v, what);
    return v;
  }
  template <class T>
  void array(std::vector<T>& v, const char* what) {
    const uint64_t n = value<uint64_t>(what);
    if (n > (data_.size() - pos_) / sizeof(T))
      throw Error(fmt::format("{}: truncated or corrupt checkpoint: {} claims {} elements, more than the {} bytes left",
                              path_, what, n, data_.size() - pos_));
    v.resize(n);
    bytes(v.data(), n * sizeof(T), what);
  }
  std::string text(const char* what, size_t maxLength) {
    const uint64_t n = value<uint64_t>(what);
    if (n > maxLength) throw Error(fmt::format("{}: corrupt checkpoint: {} of {} bytes", path_, what, n));
    std::string s(n, '\0');
    bytes(s.data(), n, what);
    return s;
  }
  bool atEnd() const { return pos_ == data_.size(); }
  const std::string& path() const { return path_; }

 private:
  const std::string& path_;
  const std::string& data_;
  size_t pos_ = 0;
};

void writeState(Writer& w, const State& s) {
  w.value(s.time);
  w.value(s.stepCount);
  w.value(s.nextId);
  w.value(int32_t{s.fluidIterations});
  const Particles& p = s.particles;
  w.array(p.phase), w.array(p.id), w.array(p.mass), w.array(p.invMass), w.array(p.radius);
  w.array(p.x), w.array(p.xPred), w.array(p.v);
  const WaterLedger& l = s.ledger;
  w.value(l.emitted), w.value(l.removedAtBounds), w.value(l.particlesRemovedAtBounds), w.value(l.heldInCloth);
  w.value(l.inBuffers), w.value(l.particlesAbsorbed), w.value(l.dripsEmitted), w.value(l.takenByCloth);
  w.value(l.particlesTakenByCloth);
  w.value(uint64_t{s.emitters.size()});
  for (const EmitterState& e : s.emitters) w.value(e.emittedLength), w.value(e.dropsEmitted), w.value(uint8_t{e.done});
  w.array(s.clothWater), w.array(s.clothBuffer), w.array(s.clothSaturation);
  w.array(s.dripId), w.array(s.dripSource), w.array(s.clothWetStart), w.array(s.clothVelocityChange);
}

void readParticles(Reader& r, Particles& p) {
  r.array(p.phase, "phase"), r.array(p.id, "id"), r.array(p.mass, "mass"), r.array(p.invMass, "invMass");
  r.array(p.radius, "radius"), r.array(p.x, "x"), r.array(p.xPred, "xPred"), r.array(p.v, "v");
  const size_t n = p.phase.size();
  for (size_t size : {p.id.size(), p.mass.size(), p.invMass.size(), p.radius.size(), p.x.size(), p.xPred.size(), p.v.size()})
    if (size != n) throw Error(fmt::format("{}: corrupt checkpoint: particle arrays of {} and {} elements", r.path(), n, size));
}

void readState(Reader& r, State& s) {
  s.time = r.value<double>("time");
  s.stepCount = r.value<uint64_t>("stepCount");
  s.nextId = r.value<uint32_t>("nextId");
  s.fluidIterations = r.value<int32_t>("fluidIterations");
  readParticles(r, s.particles);
  WaterLedger& l = s.ledger;
  l.emitted = r.value<double>("ledger"), l.removedAtBounds = r.value<double>("ledger");
  l.particlesRemovedAtBounds = r.value<uint64_t>("ledger"), l.heldInCloth = r.value<double>("ledger");
  l.inBuffers = r.value<double>("ledger"), l.particlesAbsorbed = r.value<uint64_t>("ledger");
  l.dripsEmitted = r.value<uint64_t>("ledger"), l.takenByCloth = r.value<double>("ledger");
  l.particlesTakenByCloth = r.value<uint64_t>("ledger");
  const uint64_t emitters = r.value<uint64_t>("emitters");
  if (emitters > 1u << 20) throw Error(fmt::format("{}: corrupt checkpoint: {} emitters", r.path(), emitters));
  s.emitters.resize(emitters);
  for (EmitterState& e : s.emitters) {
    e.emittedLength = r.value<double>("emitter");
    e.dropsEmitted = r.value<uint64_t>("emitter");
    e.done = r.value<uint8_t>("emitter") != 0;
  }
  r.array(s.clothWater, "clothWater"), r.array(s.clothBuffer, "clothBuffer");
  r.array(s.clothSaturation, "clothSaturation"), r.array(s.dripId, "dripId"), r.array(s.dripSource, "dripSource");
  r.array(s.clothWetStart, "clothWetStart");
  r.array(s.clothVelocityChange, "clothVelocityChange");
}

// the whole file in memory, refusing what is not a regular file (a device or a pipe never ends)
std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw Error(path + ": no checkpoint there");
  if (!std::filesystem::is_regular_file(status)) throw Error(path + ": not a regular file, expected a soak checkpoint");
  return readTextFile(path);
}

}  // namespace

uint64_t textHash(std::string_view text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

void writeCheckpoint(const std::string& path, const CheckpointInfo& c, const State& state) {
  AtomicFile file(path);
  Writer w(file.out());
  w.bytes(kMagic, sizeof kMagic);
  w.value(kCheckpointFormat);
  w.value(kByteOrderMark);
  w.text(c.soakVersion);
  w.value(c.sceneHash);
  w.value(int32_t{c.frame}), w.value(int32_t{c.stepsIntoFrame});
  w.value(uint64_t{sizeof(FrameStats)});
  w.value(c.frameSoFar);
  writeState(w, state);
  w.value(stateHash(state));
  w.bytes(kEndMark, sizeof kEndMark);
  file.commit();
}

Checkpoint readCheckpoint(const std::string& path) {
  const std::string data = readWholeFile(path);
  Reader r(path, data);
  char magic[sizeof kMagic];
  r.bytes(magic, sizeof magic, "the header");
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) throw Error(path + ": not a soak checkpoint (no SOAKCKPT header)");
  const uint32_t format = r.value<uint32_t>("the format");
  if (format != kCheckpointFormat)
    throw Error(fmt::format("{}: checkpoint format {}, this soak reads format {} only", path, format, kCheckpointFormat));
  if (r.value<uint32_t>("the byte order") != kByteOrderMark)
    throw Error(path + ": checkpoint written on a machine of another byte order");
  Checkpoint cp;
  CheckpointInfo& c = cp.info;
  c.soakVersion = r.text("the soak version", kMaxVersionLength);
  c.sceneHash = r.value<uint64_t>("the scene hash");
  c.frame = r.value<int32_t>("the frame");
  c.stepsIntoFrame = r.value<int32_t>("the steps into the frame");
  if (r.value<uint64_t>("the frame statistics' size") != sizeof(FrameStats))
    throw Error(path + ": checkpoint written by a soak whose frame statistics differ from this one's");
  c.frameSoFar = r.value<FrameStats>("the frame statistics");
  if (c.frame < 0 || c.stepsIntoFrame < 0)
    throw Error(fmt::format("{}: corrupt checkpoint: frame {}, {} steps into the next", path, c.frame, c.stepsIntoFrame));
  readState(r, cp.state);
  const uint64_t hash = r.value<uint64_t>("the state hash");
  char end[sizeof kEndMark];
  r.bytes(end, sizeof end, "the end mark");
  if (std::memcmp(end, kEndMark, sizeof kEndMark) != 0 || !r.atEnd())
    throw Error(path + ": corrupt checkpoint: no end mark where the state ends");
  if (hash != stateHash(cp.state))
    throw Error(fmt::format("{}: corrupt checkpoint: the state read back hashes to {:016x}, the file says {:016x}", path,
                            stateHash(cp.state), hash));
  return cp;
}

void checkCheckpointFits(const std::string& path, const Checkpoint& c, const Model& model) {
  const State& s = c.state;
  const size_t nc = static_cast<size_t>(model.numCloth);
  const auto fail = [&](const std::string& what) {
    throw Error(path + ": the checkpoint does not belong to this scene: " + what);
  };
  if (s.particles.size() < nc) fail(fmt::format("{} particles, the scene has {} cloth particles", s.particles.size(), nc));
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i)
      if (clothPiece(s.particles.phase[i]) != static_cast<int>(k))
        fail(fmt::format("particle {} is not of cloth piece '{}'", i, piece.name));
  }
  for (size_t i = nc; i < s.particles.size(); ++i)
    if (!isWater(s.particles.phase[i])) fail(fmt::format("particle {} after the cloth is not water", i));
  if (s.emitters.size() != model.emitters.size())
    fail(fmt::format("{} emitters, the scene has {}", s.emitters.size(), model.emitters.size()));
  // a piece wetted by contact (Chen 2012) keeps wet times, held water and saturation; Shao's wetting
  // the water arrays
  const bool chen = std::any_of(model.pieces.begin(), model.pieces.end(), [](const ClothPiece& p) { return p.wetByContact; });
  const size_t wet = model.wetting.enabled || chen ? nc : 0;
  if (s.clothWater.size() != wet || s.clothBuffer.size() != wet || s.clothSaturation.size() != wet)
    fail(fmt::format("wetting arrays of {} entries, expected {}", s.clothWater.size(), wet));
  if (s.clothWetStart.size() != (chen ? nc : 0))
    fail(fmt::format("{} wet start times, expected {}", s.clothWetStart.size(), chen ? nc : 0));
  if (s.clothVelocityChange.size() != (model.hasImplicitCloth() ? nc : 0))
    fail(fmt::format("{} implicit velocity changes, expected {}", s.clothVelocityChange.size(),
                     model.hasImplicitCloth() ? nc : 0));
  if (s.dripId.size() != s.dripSource.size()) fail("drip arrays of different lengths");
}

}  // namespace soak
