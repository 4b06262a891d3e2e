// the text layer of scene loading (scene/overrides.cpp): JSON with comments, syntax errors at a line and
// column, a key repeated in one object named with its path, and "a.b.0.c=value" overrides that walk and
// create the path, parse the value as JSON or keep it as a string, and name themselves when they fail
#include "scene/overrides.hpp"

#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>

#include "scene/scene_support.hpp"

#include <string>
#include <vector>

namespace soak {
namespace {

using namespace soak::testing;

// the message of the soak::Error applying `overrides` to `doc` throws, or "" when they apply
std::string overrideError(Json doc, const std::vector<std::string>& overrides) {
  try {
    applyOverrides(doc, overrides, "f.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

std::string parseError(const std::string& text) {
  try {
    parseSceneJson(text, "f.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SceneOverrides, ChangeValuesBeforeValidation) {
  const Scene s = fromString(kSmall, {"solver.substeps=3", "cloth.0.material.thickness=0.02", "water.tensile.k=0.25",
                                      "output.water=false", "name=my run", "description=\"quoted\"",
                                      "cloth.0.pin.corners=[0, 3]"});
  EXPECT_EQ(s.model.solver.substeps, 3);
  EXPECT_FLOAT_EQ(s.model.pieces[0].material.thickness, 0.02f);
  EXPECT_FLOAT_EQ(s.model.water.tensileK, 0.25f);
  EXPECT_FALSE(s.output.water);
  EXPECT_EQ(s.name, "my run");  // not JSON: taken as a string
  EXPECT_EQ(s.description, "quoted");
  int pinned = 0;
  for (uint8_t p : s.model.clothPinned) pinned += p;
  EXPECT_EQ(pinned, 2);
  // an override is validated like the file itself
  EXPECT_HAS(errorWith("solver.substeps=0"), "test.json: at solver.substeps: expected an integer in [1, 1000], got 0");
}

TEST(SceneErrors, BadOverridesNameTheOverride) {
  EXPECT_HAS(errorWith("solver.substeps"), "test.json: at override 'solver.substeps': expected \"path=value\"");
  EXPECT_HAS(errorWith("cloth.3.name=x"), "at override 'cloth.3.name=x': index 3 is past the end of 'cloth' (1 elements)");
  EXPECT_HAS(errorWith("cloth.0.name.x=1"), "at override 'cloth.0.name.x=1': 'cloth.0.name' is a string, it has no key 'x'");
  EXPECT_HAS(errorWith("cloth.first=1"), "'cloth' is an array: expected an index, got 'first'");
  EXPECT_HAS(errorWith("solver..dt=1"), "at override 'solver..dt=1': expected a path of non-empty components");
  EXPECT_HAS(errorWith("colliders.0.type=box"), "index 0 is past the end of 'colliders'");
}

TEST(SceneErrors, ARepeatedKeyIsNamedWithItsPath) {
  // JSON parsers keep the last of two equal keys: the first value would be lost without a word
  EXPECT_HAS(loadError(R"({"solver": {"dt": 0.015, "substeps": 2, "dt": 0.01}})"),
             "test.json: at solver.dt: expected each key once in its object, got it twice");
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "rectangle"}},
                                     {"mesh": {"type": "rectangle"}, "material": {"thickness": 0.01, "thickness": 0.02}}]})"),
             "test.json: at cloth[1].material.thickness: expected each key once");
  // the same key in two objects is not a repeat
  EXPECT_EQ(loadError(R"({"cloth": [{"name": "a", "mesh": {"type": "rectangle", "size": [0.2, 0.2], "resolution": [3, 3]}},
                                    {"name": "b", "mesh": {"type": "rectangle", "size": [0.2, 0.2], "resolution": [3, 3]}}]})"),
            "");
}

TEST(SceneErrors, JsonSyntaxErrorNamesLineAndColumn) {
  const std::string msg = loadError("{\n  \"solver\": {\n    \"dt\": 0.01,\n  }\n}\n");
  EXPECT_HAS(msg, "test.json: at line 4, column 3: invalid JSON: syntax error");
  TempDir dir;
  const std::string path = dir.write("broken.json", "{\"cloth\": [\n\n  {\"mesh\" {}}\n]}");
  try {
    loadScene(path);
    FAIL() << "broken JSON loaded";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), path + ": at line 3, column");
  }
  // comments are allowed
  EXPECT_EQ(loadError(std::string("// a comment\n") + kSmall), "");
}

// missing object keys are created down the path; numeric components index arrays; a value is parsed as
// JSON (numbers, booleans, arrays, objects, null, quoted strings), anything else is kept as a string;
// overrides apply in order, so a later one wins
TEST(SceneOverrides, PathsAreWalkedAndCreatedAndValuesParsed) {
  Json doc = Json::parse(R"({"cloth": [{"name": "a"}, {"name": "b"}], "solver": {"dt": 0.01}})");
  applyOverrides(doc,
                 {"solver.substeps=3", "new.deep.key=1e-3", "cloth.1.name=c", "cloth.0.pin={\"corners\": [0, 2]}",
                  "output.water=false", "name=my run", "description=\"quoted\"", "view=null", "solver.dt=0.02",
                  "solver.dt=0.005", "empty="},
                 "f.json");
  EXPECT_EQ(doc["solver"]["substeps"], 3);
  EXPECT_DOUBLE_EQ(doc["new"]["deep"]["key"].get<double>(), 1e-3);
  EXPECT_EQ(doc["cloth"][1]["name"], "c");
  EXPECT_EQ(doc["cloth"][0]["name"], "a");
  EXPECT_EQ(doc["cloth"][0]["pin"]["corners"], Json::parse("[0, 2]"));
  EXPECT_EQ(doc["output"]["water"], false);
  EXPECT_EQ(doc["name"], "my run");
  EXPECT_EQ(doc["description"], "quoted");
  EXPECT_TRUE(doc["view"].is_null());
  EXPECT_DOUBLE_EQ(doc["solver"]["dt"].get<double>(), 0.005);  // the last of two
  EXPECT_EQ(doc["empty"], "");
  EXPECT_EQ(doc["cloth"].size(), 2u);
}

// each way an override can fail names the file, the override's text and what went wrong
TEST(SceneOverrides, ErrorsNameTheFileAndTheOverride) {
  const Json doc = Json::parse(R"({"cloth": [{"name": "a"}], "solver": {"dt": 0.01}, "list": [1, 2]})");
  EXPECT_EQ(overrideError(doc, {"solver.dt"}),
            "f.json: at override 'solver.dt': expected \"path=value\" (e.g. solver.substeps=3), got no '='");
  EXPECT_EQ(overrideError(doc, {".dt=1"}),
            "f.json: at override '.dt=1': expected a path of non-empty components separated by '.', got '.dt'");
  EXPECT_EQ(overrideError(doc, {"=1"}), "f.json: at override '=1': expected a path of non-empty components "
                                        "separated by '.', got ''");
  EXPECT_EQ(overrideError(doc, {"cloth.1.name=x"}),
            "f.json: at override 'cloth.1.name=x': index 1 is past the end of 'cloth' (1 elements)");
  EXPECT_EQ(overrideError(doc, {"cloth.name=x"}),
            "f.json: at override 'cloth.name=x': 'cloth' is an array: expected an index, got 'name'");
  EXPECT_EQ(overrideError(doc, {"solver.dt.x=1"}),
            "f.json: at override 'solver.dt.x=1': 'solver.dt' is a number, it has no key 'x'");
  EXPECT_EQ(overrideError(doc, {"list.0.x=1"}), "f.json: at override 'list.0.x=1': 'list.0' is a number, it has no key 'x'");
  EXPECT_EQ(overrideError(doc, {"colliders.0.type=box"}),
            "f.json: at override 'colliders.0.type=box': index 0 is past the end of 'colliders' (it does not exist)");
  EXPECT_EQ(overrideError(Json::parse("[1, 2]"), {"x=1"}),
            "f.json: at override 'x=1': the top level is an array: expected an index, got 'x'");
  // the first failing override stops the rest, naming itself
  EXPECT_EQ(overrideError(doc, {"solver.dt=1", "solver.dt.y=2", "nope"}),
            "f.json: at override 'solver.dt.y=2': 'solver.dt' is a number, it has no key 'y'");
}

// comments (line and block) are allowed; a key repeated in one object is named with its full path, through
// arrays of arrays, and reported once (the first), with the same key in sibling objects allowed
TEST(SceneJson, CommentsAllowedAndARepeatedKeyNamedThroughNestedArrays) {
  const Json doc = parseSceneJson("// scene\n{\"a\": /* one */ 1, \"b\": [[{\"k\": 1}, {\"k\": 2}]]}\n", "f.json");
  EXPECT_EQ(doc["a"], 1);
  EXPECT_EQ(doc["b"][0][1]["k"], 2);
  EXPECT_EQ(parseError(R"({"b": [[{"k": 1}], [{"j": 0, "k": 1, "k": 2}]]})"),
            "f.json: at b[1][0].k: expected each key once in its object, got it twice (JSON keeps only the last)");
  EXPECT_EQ(parseError(R"({"x": 1, "y": {"x": 2}, "x": 3, "y": 4})"),
            "f.json: at x: expected each key once in its object, got it twice (JSON keeps only the last)");
}

// the line and column of a syntax error count from 1, past earlier lines of any length
TEST(SceneJson, SyntaxErrorLineAndColumn) {
  EXPECT_HAS(parseError("{\"a\": 1,\n\"b\": 2,\n     \"c\" }"), "f.json: at line 3, column 10: invalid JSON: syntax error");
  EXPECT_HAS(parseError("{\"a\": tru}"), "f.json: at line 1, column ");
  EXPECT_HAS(parseError(""), "f.json: at line 1, column 1: invalid JSON");
  EXPECT_EQ(parseError("{\"a\": 1}"), "");
}

}  // namespace
}  // namespace soak
