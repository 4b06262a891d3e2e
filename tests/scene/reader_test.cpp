// the checked JSON reader: typed reads, ranges, defaults, unknown keys, paths in messages
#include "scene/reader.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

namespace soak {
namespace {

std::string allErrors(const ErrorLog& log) {
  std::string s;
  for (const auto& m : log.messages()) s += m + "\n";
  return s;
}

TEST(SceneReader, ReadsTypedValuesAndDefaults) {
  const Json j = Json::parse(R"({"a": 2.5, "n": 3, "b": true, "s": "hi", "v": [1, 2, 3], "d": [0, 0, -2],
                                "e": "box", "sub": {"x": 1}})");
  ErrorLog log("f.json");
  ObjectReader r(log, &j, "");
  EXPECT_FLOAT_EQ(r.number("a", 1.0f, Range::positive()), 2.5f);
  EXPECT_FLOAT_EQ(r.number("missing", 7.0f), 7.0f);
  EXPECT_EQ(r.integer("n", 1, Range::atLeast(1)), 3);
  EXPECT_TRUE(r.boolean("b", false));
  EXPECT_EQ(r.string("s", ""), "hi");
  EXPECT_TRUE(r.vec3("v", Vec3::Zero()).isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(r.unitVec3("d", Vec3::UnitX()).isApprox(Vec3(0, 0, -1)));
  EXPECT_EQ(r.choice("e", {"plane", "box"}, "plane"), 1);
  ObjectReader sub = r.object("sub");
  EXPECT_EQ(sub.integer("x", 0), 1);
  sub.finish();
  r.finish();
  EXPECT_TRUE(log.ok()) << allErrors(log);
}

TEST(SceneReader, RangeAndTypeErrorsNameFileAndPath) {
  const Json j = Json::parse(R"({"solver": {"dt": -1, "substeps": 1.5, "gravity": [0, 1], "on": 1,
                                "axis": [0, 0, 0], "kind": "cube"}})");
  ErrorLog log("bad.json");
  ObjectReader top(log, &j, "");
  ObjectReader r = top.object("solver");
  EXPECT_FLOAT_EQ(r.number("dt", 0.015f, Range::positive()), 0.015f);  // falls back to the default
  r.integer("substeps", 1, Range::atLeast(1));
  r.vec3("gravity", Vec3::Zero());
  r.boolean("on", false);
  r.unitVec3("axis", Vec3::UnitY());
  EXPECT_EQ(r.choice("kind", {"plane", "box"}, std::nullopt), -1);
  r.finish();
  top.finish();
  const auto& m = log.messages();
  ASSERT_EQ(m.size(), 6u) << allErrors(log);
  EXPECT_EQ(m[0], "bad.json: at solver.dt: expected a number > 0, got -1");
  EXPECT_EQ(m[1], "bad.json: at solver.substeps: expected an integer >= 1, got 1.5");
  EXPECT_EQ(m[2], "bad.json: at solver.gravity: expected an array of 3 numbers, got [0,1]");
  EXPECT_EQ(m[3], "bad.json: at solver.on: expected true or false, got 1");
  EXPECT_EQ(m[4], "bad.json: at solver.axis: expected a non-zero direction (an array of 3 numbers), got [0,0,0]");
  EXPECT_EQ(m[5], "bad.json: at solver.kind: expected one of \"plane\", \"box\", got the string \"cube\"");
  EXPECT_THROW(log.throwIfAny(), Error);
}

TEST(SceneReader, UnknownKeysListTheKnownOnesAndSuggest) {
  const Json j = Json::parse(R"({"dt": 0.01, "substep": 2})");
  ErrorLog log("u.json");
  ObjectReader r(log, &j, "solver");
  r.number("dt", 0.015f);
  r.integer("substeps", 1);
  r.integer("fluidIterations", 4);
  r.finish();
  ASSERT_EQ(log.messages().size(), 1u);
  EXPECT_EQ(log.messages()[0],
            "u.json: at solver.substep: unknown key 'substep' (known: dt, substeps, fluidIterations); "
            "did you mean 'substeps'?");
}

TEST(SceneReader, KeysOfOtherVariantsAreNamedAsSuch) {
  const Json j = Json::parse(R"({"type": "box", "radius": 0.2})");
  ErrorLog log("c.json");
  ObjectReader r(log, &j, "colliders[1]");
  r.choice("type", {"box", "sphere"}, std::nullopt);
  r.vec3("halfExtents", Vec3::Ones());
  r.finish({"radius"}, "a box collider");
  ASSERT_EQ(log.messages().size(), 1u);
  EXPECT_EQ(log.messages()[0],
            "c.json: at colliders[1].radius: 'radius' is not a key of a box collider (keys of a box collider: "
            "type, halfExtents)");
}

TEST(SceneReader, RequiredKeysAndIntegerArrays) {
  const Json j = Json::parse(R"({"resolution": [1, 4], "size": [1, 2]})");
  ErrorLog log("r.json");
  ObjectReader r(log, &j, "mesh");
  r.integers("resolution", 2, std::nullopt, Range::atLeast(2));
  const auto size = r.numbers("size", 2, std::nullopt, Range::positive());
  EXPECT_FLOAT_EQ(size[1], 2.0f);
  r.vec3("center", std::nullopt);
  r.finish();
  ASSERT_EQ(log.messages().size(), 2u) << allErrors(log);
  EXPECT_EQ(log.messages()[0], "r.json: at mesh.resolution[0]: expected an integer >= 2, got 1");
  EXPECT_EQ(log.messages()[1], "r.json: at mesh.center: expected an array of 3 numbers, got nothing (the key is "
                               "required)");
}

TEST(SceneReader, RangeDescriptions) {
  EXPECT_EQ(Range::unit().describe(false), "a number in [0, 1]");
  EXPECT_EQ(Range::atLeast(0).describe(true), "an integer >= 0");
  EXPECT_EQ(Range::any().describe(false), "a number");
  EXPECT_TRUE(Range::positive().contains(1e-9));
  EXPECT_FALSE(Range::positive().contains(0.0));
  EXPECT_TRUE(Range::unit().contains(1.0));
  EXPECT_FALSE(Range::unit().contains(1.0001));
}

}  // namespace
}  // namespace soak
