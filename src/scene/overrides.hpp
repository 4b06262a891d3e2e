// the text layer of scene loading: JSON parsing with line/column errors and "a.b.0.c=value" overrides
#pragma once
#include "scene/reader.hpp"

#include <string>
#include <vector>

namespace soak {

// parses JSON text (comments allowed); a syntax error throws soak::Error
// "<file>: at line L, column C: invalid JSON: <what>", a key repeated in one object
// "<file>: at <path>: expected each key once in its object, ..."
Json parseSceneJson(const std::string& text, const std::string& file);

// applies "a.b.0.c=value" overrides in order: walks the path (numeric components index arrays,
// missing object keys are created), parses value as JSON, else takes it as a string. An override
// without '=', with an empty component, indexing past an array or descending into a non-container
// throws soak::Error "<file>: at override '<text>': <what>".
void applyOverrides(Json& doc, const std::vector<std::string>& overrides, const std::string& file);

}  // namespace soak
