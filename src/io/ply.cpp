#include "io/ply.hpp"

#include "io/file.hpp"
#include "io/obj.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>
#include <sstream>

namespace soak {

namespace {

// appends the little-endian bytes of a value
template <class T>
void put(std::vector<char>& buf, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  buf.insert(buf.end(), bytes, bytes + sizeof(T));
}

void putVec(std::vector<char>& buf, const Vec3& v) {
  put(buf, v.x());
  put(buf, v.y());
  put(buf, v.z());
}

bool validName(const std::string& s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

void writeAll(const std::string& path, const std::string& header, const std::vector<char>& body) {
  AtomicFile file(path);
  file.out().write(header.data(), static_cast<std::streamsize>(header.size()));
  file.out().write(body.data(), static_cast<std::streamsize>(body.size()));
  file.commit();
}

}  // namespace

void writeClothPly(const std::string& path, const Model& model, const State& state, std::span<const Vec3> normals,
                   std::span<const PlyFloatAttribute> extras) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  const Particles& p = state.particles;
  if (p.size() < nc)
    throw Error(fmt::format("{}: state has {} particles, model has {} cloth particles", path, p.size(), nc));
  if (!normals.empty() && normals.size() != nc)
    throw Error(fmt::format("{}: expected {} normals, got {}", path, nc, normals.size()));
  static const char* kFixed[] = {"x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz", "piece", "pinned"};
  for (size_t k = 0; k < extras.size(); ++k) {
    const PlyFloatAttribute& a = extras[k];
    if (!validName(a.name))
      throw Error(fmt::format("{}: extra attribute '{}': expected a name of letters, digits and _", path, a.name));
    const bool clash = std::any_of(std::begin(kFixed), std::end(kFixed), [&](const char* f) { return a.name == f; }) ||
                       std::any_of(extras.begin(), extras.begin() + static_cast<long>(k),
                                   [&](const PlyFloatAttribute& b) { return b.name == a.name; });
    if (clash) throw Error(fmt::format("{}: extra attribute '{}' is defined twice", path, a.name));
    if (a.values.size() != nc)
      throw Error(fmt::format("{}: extra attribute '{}': expected {} values, got {}", path, a.name, nc,
                              a.values.size()));
  }
  std::vector<Vec3> own;
  if (normals.empty()) {
    own = clothVertexNormals(model, p.x);
    normals = own;
  }

  std::string header = "ply\nformat binary_little_endian 1.0\ncomment soak cloth, SI units (m, m/s)\n";
  header += fmt::format("element vertex {}\n", nc);
  header +=
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property float vx\nproperty float vy\nproperty float vz\n"
      "property int piece\nproperty uchar pinned\n";
  for (const PlyFloatAttribute& a : extras) header += "property float " + a.name + "\n";
  header += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                        model.triangles.size());

  const size_t vertexBytes = 9 * 4 + 4 + 1 + 4 * extras.size();
  std::vector<char> body;
  body.reserve(nc * vertexBytes + model.triangles.size() * 13);
  for (size_t i = 0; i < nc; ++i) {
    putVec(body, p.x[i]);
    putVec(body, normals[i]);
    putVec(body, p.v[i]);
    put<int32_t>(body, clothPiece(p.phase[i]));
    put<uint8_t>(body, i < model.clothPinned.size() ? model.clothPinned[i] : uint8_t{0});
    for (const PlyFloatAttribute& a : extras) put<float>(body, a.values[i]);
  }
  for (const auto& t : model.triangles) {
    put<uint8_t>(body, 3);
    for (int k = 0; k < 3; ++k) put<int32_t>(body, t[k]);
  }
  writeAll(path, header, body);
}

void writeWaterPly(const std::string& path, const State& state) {
  const Particles& p = state.particles;
  size_t n = 0;
  for (size_t i = 0; i < p.size(); ++i) n += isWater(p.phase[i]) ? 1 : 0;
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment soak water, SI units (m, m/s, kg)\n";
  header += fmt::format("element vertex {}\n", n);
  header +=
      "property float x\nproperty float y\nproperty float z\n"
      "property float vx\nproperty float vy\nproperty float vz\n"
      "property float mass\nproperty float radius\nproperty uint id\nend_header\n";
  std::vector<char> body;
  body.reserve(n * 36);
  for (size_t i = 0; i < p.size(); ++i) {
    if (!isWater(p.phase[i])) continue;
    putVec(body, p.x[i]);
    putVec(body, p.v[i]);
    put<float>(body, p.mass[i]);
    put<float>(body, p.radius[i]);
    put<uint32_t>(body, p.id[i]);
  }
  writeAll(path, header, body);
}

// ---- reader ----

const std::vector<double>& PlyElement::scalar(const std::string& property) const {
  const auto it = scalars.find(property);
  if (it == scalars.end()) throw Error("PLY element '" + name + "' has no scalar property '" + property + "'");
  return it->second;
}

bool PlyData::has(const std::string& name) const {
  return std::any_of(elements.begin(), elements.end(), [&](const PlyElement& e) { return e.name == name; });
}

const PlyElement& PlyData::element(const std::string& name) const {
  for (const PlyElement& e : elements)
    if (e.name == name) return e;
  throw Error(path + ": no element '" + name + "'");
}

namespace {

enum class PlyType { Char, UChar, Short, UShort, Int, UInt, Float, Double, Invalid };

PlyType parseType(const std::string& s) {
  if (s == "char" || s == "int8") return PlyType::Char;
  if (s == "uchar" || s == "uint8") return PlyType::UChar;
  if (s == "short" || s == "int16") return PlyType::Short;
  if (s == "ushort" || s == "uint16") return PlyType::UShort;
  if (s == "int" || s == "int32") return PlyType::Int;
  if (s == "uint" || s == "uint32") return PlyType::UInt;
  if (s == "float" || s == "float32") return PlyType::Float;
  if (s == "double" || s == "float64") return PlyType::Double;
  return PlyType::Invalid;
}

size_t typeSize(PlyType t) {
  switch (t) {
    case PlyType::Char: case PlyType::UChar: return 1;
    case PlyType::Short: case PlyType::UShort: return 2;
    case PlyType::Int: case PlyType::UInt: case PlyType::Float: return 4;
    case PlyType::Double: return 8;
    default: return 0;
  }
}

struct PropertySpec {
  std::string name;
  PlyType type = PlyType::Invalid;       // scalar type, or list item type
  PlyType countType = PlyType::Invalid;  // list count type; Invalid for a scalar
};

// reads values from the body of a binary or ascii file
class BodyReader {
 public:
  BodyReader(const std::string& path, const std::string& data, size_t pos, bool ascii, bool bigEndian)
      : path_(path), data_(data), pos_(pos), ascii_(ascii), big_(bigEndian) {}

  double read(PlyType t, const std::string& where) {
    if (ascii_) return readAscii(where);
    const size_t n = typeSize(t);
    if (pos_ + n > data_.size()) throw Error(path_ + ": at " + where + ": file ends early");
    char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
    switch (t) {
      case PlyType::Char: { int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::UChar: { uint8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::Short: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::UShort: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::Int: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::UInt: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Float: { float v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Double: { double v; std::memcpy(&v, b, 8); return v; }
      default: throw Error(path_ + ": at " + where + ": invalid type");
    }
  }
  size_t remaining() const { return data_.size() - pos_; }

 private:
  double readAscii(const std::string& where) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    const size_t begin = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (begin == pos_) throw Error(path_ + ": at " + where + ": file ends early");
    const std::string token = data_.substr(begin, pos_ - begin);
    try {
      size_t used = 0;
      const double v = std::stod(token, &used);
      if (used != token.size()) throw std::invalid_argument(token);
      return v;
    } catch (const std::exception&) {
      throw Error(path_ + ": at " + where + ": expected a number, got '" + token + "'");
    }
  }

  const std::string& path_;
  const std::string& data_;
  size_t pos_;
  bool ascii_, big_;
};

// a "property" line of the header (ss past the word): a scalar type or "list COUNT ITEM", then the
// name, added to the last element
void readPropertyLine(std::istringstream& ss, const std::string& path, const std::string& where, PlyData& ply,
                      std::vector<std::vector<PropertySpec>>& specs) {
  if (ply.elements.empty()) throw Error(path + ": at " + where + ": property before any element");
  PropertySpec spec;
  std::string type;
  ss >> type;
  std::string typeName = type;
  if (type == "list") {
    std::string countType, itemType;
    ss >> countType >> itemType;
    spec.countType = parseType(countType);
    spec.type = parseType(itemType);
    if (spec.countType == PlyType::Invalid || spec.type == PlyType::Invalid)
      throw Error(path + ": at " + where + ": unknown list types '" + countType + " " + itemType + "'");
    typeName = "list " + countType + " " + itemType;
  } else {
    spec.type = parseType(type);
    if (spec.type == PlyType::Invalid) throw Error(path + ": at " + where + ": unknown type '" + type + "'");
  }
  ss >> spec.name;
  if (spec.name.empty()) throw Error(path + ": at " + where + ": property has no name");
  PlyElement& e = ply.elements.back();
  if (e.has(spec.name)) throw Error(path + ": at " + where + ": property '" + spec.name + "' defined twice");
  e.propertyNames.push_back(spec.name);
  e.propertyType[spec.name] = typeName;
  specs.back().push_back(spec);
}

// the header up to end_header: format, comments, the elements and their properties (specs, one list
// per element); returns the offset of the body
size_t readHeader(const std::string& data, const std::string& path, PlyData& ply,
                  std::vector<std::vector<PropertySpec>>& specs) {
  size_t pos = 0;
  int lineNo = 0;
  bool ended = false;
  while (!ended) {
    const size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) throw Error(path + ": header has no end_header line");
    std::string line = data.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = eol + 1;
    ++lineNo;
    const std::string where = "header line " + std::to_string(lineNo);
    std::istringstream ss(line);
    std::string word;
    ss >> word;
    if (lineNo == 1) {
      if (word != "ply") throw Error(path + ": at " + where + ": expected 'ply', not a PLY file");
      continue;
    }
    if (word == "format") {
      std::string version;
      ss >> ply.format >> version;
      if (ply.format != "ascii" && ply.format != "binary_little_endian" && ply.format != "binary_big_endian")
        throw Error(path + ": at " + where + ": unknown format '" + ply.format + "'");
    } else if (word == "comment" || word == "obj_info") {
      ply.comments.push_back(line.size() > word.size() + 1 ? line.substr(word.size() + 1) : std::string());
    } else if (word == "element") {
      PlyElement e;
      long long count = -1;
      ss >> e.name >> count;
      if (e.name.empty() || count < 0) throw Error(path + ": at " + where + ": expected 'element NAME COUNT'");
      e.count = static_cast<size_t>(count);
      ply.elements.push_back(std::move(e));
      specs.emplace_back();
    } else if (word == "property") {
      readPropertyLine(ss, path, where, ply, specs);
    } else if (word == "end_header") {
      ended = true;
    } else if (!word.empty()) {
      throw Error(path + ": at " + where + ": unexpected '" + word + "'");
    }
  }
  if (ply.format.empty()) throw Error(path + ": header has no format line");
  return pos;
}

// the items of one element from the body: scalars into e.scalars, lists into e.listValues with their
// offsets in e.listStart
void readElement(BodyReader& body, const std::string& path, const std::string& format, PlyElement& e,
                 const std::vector<PropertySpec>& props) {
  // a corrupt count must not make us allocate far more than the file holds
  size_t minBytes = 0;
  for (const PropertySpec& s : props) minBytes += typeSize(s.countType == PlyType::Invalid ? s.type : s.countType);
  if (format != "ascii" && minBytes > 0 && e.count > body.remaining() / minBytes)
    throw Error(fmt::format("{}: element '{}' declares {} items but the file is too short", path, e.name, e.count));
  std::vector<std::vector<double>*> scalarOut(props.size(), nullptr);
  for (size_t j = 0; j < props.size(); ++j) {
    if (props[j].countType == PlyType::Invalid) {
      scalarOut[j] = &e.scalars[props[j].name];
      scalarOut[j]->reserve(e.count);
    } else {
      e.listStart[props[j].name].push_back(0);
    }
  }
  for (size_t i = 0; i < e.count; ++i) {
    for (size_t j = 0; j < props.size(); ++j) {
      const PropertySpec& s = props[j];
      const std::string where = fmt::format("element '{}' item {} property '{}'", e.name, i, s.name);
      if (scalarOut[j]) {
        scalarOut[j]->push_back(body.read(s.type, where));
        continue;
      }
      const double c = body.read(s.countType, where);
      if (c < 0) throw Error(path + ": at " + where + ": negative list length");
      auto& values = e.listValues[s.name];
      for (size_t m = 0; m < static_cast<size_t>(c); ++m)
        values.push_back(static_cast<int64_t>(body.read(s.type, where)));
      e.listStart[s.name].push_back(values.size());
    }
  }
}

}  // namespace

PlyData readPly(const std::string& path) {
  const std::string data = readTextFile(path);
  PlyData ply;
  ply.path = path;
  std::vector<std::vector<PropertySpec>> specs;
  const size_t pos = readHeader(data, path, ply, specs);
  BodyReader body(path, data, pos, ply.format == "ascii", ply.format == "binary_big_endian");
  for (size_t k = 0; k < ply.elements.size(); ++k) readElement(body, path, ply.format, ply.elements[k], specs[k]);
  return ply;
}

}  // namespace soak
