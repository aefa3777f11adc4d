#pragma once

/// \file
/// \brief Helpers shared by the content-format tests.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/formats/model.h"
#include "runtime/formats/text.h"

namespace basalt::formats::test {

/// \brief Load options for tests: warnings are returned, not logged.
LoadOptions quiet();

/// \brief The shared test data's `models` folder, or empty when it is not on this machine.
std::filesystem::path modelsDir();

/// \brief True when some warning's text (where + message) contains `text`.
bool hasWarning(const std::vector<Diagnostic>& warnings, std::string_view text);

/// \brief All warnings, one per line, for failure messages.
std::string listWarnings(const std::vector<Diagnostic>& warnings);

/// \brief Parses OBJ text from memory (folder: the current directory).
Result<LoadedModel> obj(std::string_view text, const std::string& name = "test.obj");

/// \brief The first object's mesh (asserting there is one is the caller's job).
const runtime::Mesh& firstMesh(const LoadedModel& model);

/// \brief The whole content of a file ("" when it cannot be read).
std::string readText(const std::filesystem::path& path);

/// \brief Sum of the areas of a mesh's triangles.
double triangleArea(const runtime::Mesh& mesh);

}  // namespace basalt::formats::test
