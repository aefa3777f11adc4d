#include "formats_test_util.h"

#include <cmath>
#include <cstdio>

#include "support/test_paths.h"

namespace basalt::formats::test {

LoadOptions quiet() {
  LoadOptions o;
  o.logWarnings = false;
  return o;
}

std::filesystem::path modelsDir() {
  const auto data = basalt::test::testdataDir();
  return data.empty() ? data : data / "models";
}

bool hasWarning(const std::vector<Diagnostic>& warnings, std::string_view text) {
  for (const Diagnostic& d : warnings) {
    if (d.describe().find(text) != std::string::npos) return true;
  }
  return false;
}

std::string listWarnings(const std::vector<Diagnostic>& warnings) {
  std::string out;
  for (const Diagnostic& d : warnings) out += "  " + d.describe() + "\n";
  return out.empty() ? "  (no warnings)\n" : out;
}

Result<LoadedModel> obj(std::string_view text, const std::string& name) {
  return parseObjText(text, name, std::filesystem::current_path(), quiet());
}

const runtime::Mesh& firstMesh(const LoadedModel& model) { return *model.objects.at(0).mesh; }

std::string readText(const std::filesystem::path& path) {
  std::string out;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) out.append(buffer, n);
  std::fclose(f);
  return out;
}

double triangleArea(const runtime::Mesh& mesh) {
  double area = 0;
  for (std::size_t i = 0; i + 2 < mesh.triangles.size(); i += 3) {
    const Vec3 a = mesh.positions[mesh.triangles[i]], b = mesh.positions[mesh.triangles[i + 1]],
               c = mesh.positions[mesh.triangles[i + 2]];
    area += 0.5 * static_cast<double>(length(cross(b - a, c - a)));
  }
  return area;
}

}  // namespace basalt::formats::test
