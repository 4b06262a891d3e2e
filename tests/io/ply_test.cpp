// PLY output and the reader (io/ply.cpp): cloth and water round trips, ascii and big-endian input with
// every scalar type, extra attributes, and each malformed header, short body or missing property named
// with the file and the line or element
#include "io/ply.hpp"

#include "io/obj.hpp"

#include <gtest/gtest.h>

#include <soak/error.hpp>
#include <soak/output.hpp>

#include "io/io_support.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace soak {
namespace {

using namespace soak::testing;

// the big-endian bytes of a value
template <class T>
std::string be(T value) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  std::string s(b, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(s.begin(), s.end());
  return s;
}

// the message of the soak::Error readPly throws on a file holding `text`
std::string readError(const fs::path& dir, const std::string& text) {
  const std::string path = (dir / "bad.ply").string();
  writeTextFile(path, text);
  try {
    readPly(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(IoPly, ClothRoundTripsThroughReader) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("clothply");
  const std::string path = (dir / "cloth_0001.ply").string();
  std::vector<float> saturation(13);
  for (int i = 0; i < 13; ++i) saturation[i] = 0.05f * i;
  const PlyFloatAttribute extra[] = {{"saturation", saturation}};
  writeClothPly(path, f.model, f.state, {}, extra);
  const PlyData ply = readPly(path);
  EXPECT_EQ(ply.format, "binary_little_endian");
  const PlyElement& v = ply.element("vertex");
  ASSERT_EQ(v.count, 13u);
  EXPECT_EQ(v.propertyNames, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz", "piece",
                                                       "pinned", "saturation"}));
  EXPECT_EQ(v.propertyType.at("piece"), "int");
  EXPECT_EQ(v.propertyType.at("pinned"), "uchar");
  const std::vector<Vec3> normals = clothVertexNormals(f.model, f.state.particles.x);
  for (int i = 0; i < 13; ++i) {
    EXPECT_EQ(v.scalar("x")[i], f.state.particles.x[i].x());
    EXPECT_EQ(v.scalar("y")[i], f.state.particles.x[i].y());
    EXPECT_EQ(v.scalar("z")[i], f.state.particles.x[i].z());
    EXPECT_EQ(v.scalar("nx")[i], normals[i].x());
    EXPECT_EQ(v.scalar("ny")[i], normals[i].y());
    EXPECT_EQ(v.scalar("vx")[i], f.state.particles.v[i].x());
    EXPECT_EQ(v.scalar("vz")[i], f.state.particles.v[i].z());
    EXPECT_EQ(v.scalar("piece")[i], i < 9 ? 0 : 1);
    EXPECT_EQ(v.scalar("pinned")[i], f.model.clothPinned[i]);
    EXPECT_EQ(v.scalar("saturation")[i], saturation[i]);
  }
  // the fixture pins the first row of the sheet only
  EXPECT_EQ(v.scalar("pinned")[0], 1);
  EXPECT_EQ(v.scalar("pinned")[9], 0);
  const PlyElement& faces = ply.element("face");
  ASSERT_EQ(faces.count, f.model.triangles.size());
  EXPECT_EQ(faces.propertyType.at("vertex_indices"), "list uchar int");
  const auto& start = faces.listStart.at("vertex_indices");
  const auto& idx = faces.listValues.at("vertex_indices");
  for (size_t t = 0; t < faces.count; ++t) {
    ASSERT_EQ(start[t + 1] - start[t], 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(idx[start[t] + k], f.model.triangles[t][k]);  // 0-based
  }
  fs::remove_all(dir);
}

TEST(IoPly, WaterRoundTripsThroughReader) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("waterply");
  const std::string path = (dir / "water_0001.ply").string();
  writeWaterPly(path, f.state);
  const PlyData ply = readPly(path);
  ASSERT_EQ(ply.elements.size(), 1u);
  const PlyElement& v = ply.element("vertex");
  ASSERT_EQ(v.count, 5u);  // only water particles
  EXPECT_EQ(v.propertyNames,
            (std::vector<std::string>{"x", "y", "z", "vx", "vy", "vz", "mass", "radius", "id"}));
  EXPECT_EQ(v.propertyType.at("id"), "uint");
  EXPECT_EQ(v.propertyType.at("mass"), "float");
  for (int k = 0; k < 5; ++k) {
    const size_t i = 13 + k;
    EXPECT_EQ(v.scalar("id")[k], 100 + 7 * k);
    EXPECT_EQ(v.scalar("x")[k], f.state.particles.x[i].x());
    EXPECT_EQ(v.scalar("y")[k], 2.0f);
    EXPECT_EQ(v.scalar("vy")[k], f.state.particles.v[i].y());
    EXPECT_EQ(v.scalar("vz")[k], 1.5f);
    EXPECT_EQ(v.scalar("mass")[k], f.state.particles.mass[i]);
    EXPECT_EQ(v.scalar("radius")[k], f.state.particles.radius[i]);
  }
  // an empty water set is still a valid file
  State empty;
  writeWaterPly(path, empty);
  EXPECT_EQ(readPly(path).element("vertex").count, 0u);
  fs::remove_all(dir);
}

TEST(IoPly, ReaderReadsAsciiAndRejectsTruncatedFiles) {
  const fs::path dir = tempDir("plyread");
  const std::string ascii = (dir / "a.ply").string();
  writeTextFile(ascii,
                "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty uint id\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "0.5 7\n-1.25 9\n3 0 1 1\n");
  const PlyData a = readPly(ascii);
  EXPECT_EQ(a.element("vertex").scalar("x"), (std::vector<double>{0.5, -1.25}));
  EXPECT_EQ(a.element("vertex").scalar("id"), (std::vector<double>{7, 9}));
  EXPECT_EQ(a.element("face").listValues.at("vertex_indices"), (std::vector<int64_t>{0, 1, 1}));

  const Fixture f = makeFixture();
  const std::string path = (dir / "water.ply").string();
  writeWaterPly(path, f.state);
  std::string bytes = readTextFile(path);
  writeTextFile(path, bytes.substr(0, bytes.size() - 10));
  try {
    readPly(path);
    FAIL() << "a truncated PLY was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  writeTextFile(path, "not a ply\n");
  EXPECT_THROW(readPly(path), Error);
  fs::remove_all(dir);
}

TEST(IoErrors, ExtraAttributeMustMatchClothAndHaveAFreshName) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("extras");
  const std::string path = (dir / "c.ply").string();
  std::vector<float> shortValues(4), ok(13);
  const PlyFloatAttribute wrongSize[] = {{"saturation", shortValues}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, wrongSize), Error);
  const PlyFloatAttribute clash[] = {{"x", ok}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, clash), Error);
  const PlyFloatAttribute badName[] = {{"wet ness", ok}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, badName), Error);
  fs::remove_all(dir);
}

// a big-endian file with every scalar type and a list counted by a ushort reads back exactly
TEST(IoPly, BigEndianWithEveryScalarType) {
  const fs::path dir = tempDir("plybe");
  const std::string path = (dir / "be.ply").string();
  std::string text =
      "ply\r\nformat binary_big_endian 1.0\r\ncomment made by hand\r\nobj_info two items\r\n"
      "element item 2\r\nproperty char c\r\nproperty uchar uc\r\nproperty short s\r\nproperty ushort us\r\n"
      "property int i\r\nproperty uint ui\r\nproperty float f\r\nproperty double d\r\n"
      "property list ushort int ids\r\nend_header\r\n";
  text += be<int8_t>(-7) + be<uint8_t>(250) + be<int16_t>(-30000) + be<uint16_t>(60000) + be<int32_t>(-2000000000) +
          be<uint32_t>(4000000000u) + be<float>(1.5f) + be<double>(-0.1) + be<uint16_t>(2) + be<int32_t>(5) +
          be<int32_t>(-6);
  text += be<int8_t>(1) + be<uint8_t>(2) + be<int16_t>(3) + be<uint16_t>(4) + be<int32_t>(5) + be<uint32_t>(6) +
          be<float>(7.0f) + be<double>(8.0) + be<uint16_t>(0);
  writeTextFile(path, text);
  const PlyData ply = readPly(path);
  EXPECT_EQ(ply.format, "binary_big_endian");
  EXPECT_EQ(ply.comments, (std::vector<std::string>{"made by hand", "two items"}));
  const PlyElement& e = ply.element("item");
  ASSERT_EQ(e.count, 2u);
  EXPECT_EQ(e.scalar("c"), (std::vector<double>{-7, 1}));
  EXPECT_EQ(e.scalar("uc"), (std::vector<double>{250, 2}));
  EXPECT_EQ(e.scalar("s"), (std::vector<double>{-30000, 3}));
  EXPECT_EQ(e.scalar("us"), (std::vector<double>{60000, 4}));
  EXPECT_EQ(e.scalar("i"), (std::vector<double>{-2000000000, 5}));
  EXPECT_EQ(e.scalar("ui"), (std::vector<double>{4000000000.0, 6}));
  EXPECT_EQ(e.scalar("f"), (std::vector<double>{1.5, 7}));
  EXPECT_EQ(e.scalar("d"), (std::vector<double>{-0.1, 8}));
  EXPECT_EQ(e.propertyType.at("ids"), "list ushort int");
  EXPECT_EQ(e.listStart.at("ids"), (std::vector<size_t>{0, 2, 2}));
  EXPECT_EQ(e.listValues.at("ids"), (std::vector<int64_t>{5, -6}));
  EXPECT_FALSE(e.has("x"));
  fs::remove_all(dir);
}

// each malformed header names the file and the header line, and says what is wrong
TEST(IoPly, MalformedHeadersNameTheFileAndTheLine) {
  const fs::path dir = tempDir("plyheader");
  const std::string path = (dir / "bad.ply").string();
  const std::string fmt = "ply\nformat ascii 1.0\n";
  EXPECT_EQ(readError(dir, "ply\nformat ascii 1.0\nelement v 1\n"), path + ": header has no end_header line");
  EXPECT_EQ(readError(dir, "ply\nformat binary 1.0\nend_header\n"), path + ": at header line 2: unknown format 'binary'");
  EXPECT_EQ(readError(dir, fmt + "property float x\nend_header\n"),
            path + ": at header line 3: property before any element");
  EXPECT_EQ(readError(dir, fmt + "element v 1\nproperty half x\nend_header\n"),
            path + ": at header line 4: unknown type 'half'");
  EXPECT_EQ(readError(dir, fmt + "element v 1\nproperty list uchar half ids\nend_header\n"),
            path + ": at header line 4: unknown list types 'uchar half'");
  EXPECT_EQ(readError(dir, fmt + "element v 1\nproperty float x\nproperty float x\nend_header\n"),
            path + ": at header line 5: property 'x' defined twice");
  EXPECT_EQ(readError(dir, fmt + "element v 1\nproperty float\nend_header\n"), path + ": at header line 4: property has no name");
  EXPECT_EQ(readError(dir, fmt + "element v\nend_header\n"), path + ": at header line 3: expected 'element NAME COUNT'");
  EXPECT_EQ(readError(dir, fmt + "vertices 3\nend_header\n"), path + ": at header line 3: unexpected 'vertices'");
  EXPECT_EQ(readError(dir, "ply\nelement v 0\nend_header\n"), path + ": header has no format line");
  EXPECT_EQ(readError(dir, "PLY\nformat ascii 1.0\nend_header\n"), path + ": at header line 1: expected 'ply', not a PLY file");
  fs::remove_all(dir);
}

// the body: a count larger than a binary file can hold is refused before anything is allocated; an ascii
// token that is not a number, or a file that ends early, names the element, item and property
TEST(IoPly, ShortOrMalformedBodiesNameTheElementItemAndProperty) {
  const fs::path dir = tempDir("plybody");
  const std::string path = (dir / "bad.ply").string();
  EXPECT_EQ(readError(dir, "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                           "end_header\n0123456789"),
            path + ": element 'vertex' declares 1000000000 items but the file is too short");
  EXPECT_EQ(readError(dir, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                           "end_header\n1 2\n3 abc\n"),
            path + ": at element 'vertex' item 1 property 'y': expected a number, got 'abc'");
  EXPECT_EQ(readError(dir, "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                           "end_header\n3 0 1\n"),
            path + ": at element 'face' item 0 property 'vertex_indices': file ends early");
  fs::remove_all(dir);
}

// a missing element or scalar property is an error naming it (and the file, for the element)
TEST(IoPly, MissingElementOrPropertyIsNamed) {
  const fs::path dir = tempDir("plymissing");
  const std::string path = (dir / "w.ply").string();
  writeWaterPly(path, makeFixture().state);
  const PlyData ply = readPly(path);
  EXPECT_TRUE(ply.has("vertex"));
  EXPECT_FALSE(ply.has("face"));
  try {
    ply.element("face");
    FAIL() << "found an element the file does not have";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": no element 'face'");
  }
  try {
    ply.element("vertex").scalar("saturation");
    FAIL() << "found a property the file does not have";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "PLY element 'vertex' has no scalar property 'saturation'");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace soak
