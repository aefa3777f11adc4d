#include "script_support.h"

#include <fmt/format.h>

namespace basalt::script::test {

std::shared_ptr<const runtime::Mesh> makeBoat() {
  auto mesh = std::make_shared<runtime::Mesh>();
  const Vec3 corners[] = {{-1, -0.2f, 0}, {1, -0.2f, 0},   {1, 0.2f, 0},    {-1, 0.2f, 0},
                          {0, 0.2f, 0},   {0.1f, 0.2f, 0}, {0.1f, 1.2f, 0}, {0, 1.2f, 0}};
  for (const Vec3& c : corners) {
    mesh->positions.push_back(c);
    mesh->normals.push_back({0, 0, 1});
  }
  for (std::uint32_t p = 0; p < 2; ++p) {
    runtime::MeshPart part;
    part.name = p == 0 ? "hull" : "mast";
    part.firstTriangleIndex = static_cast<std::uint32_t>(mesh->triangles.size());
    const std::uint32_t b = p * 4;
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh->triangles.push_back(b + i);
    part.triangleIndexCount = 6;
    part.facetCount = 1;
    mesh->parts.push_back(part);
  }
  return mesh;
}

Result<void> RecordingHost::loadObject(const std::filesystem::path& file, runtime::Show& show) {
  objects.push_back(file);
  if (failObjects) return fail(Errc::kNotFound, "no such file", file.string());
  show.clear();
  runtime::SceneNode node;
  node.name = "boat";
  node.mesh = makeBoat();
  show.addNode(std::move(node));
  return {};
}

Result<void> RecordingHost::loadTexture(const std::filesystem::path& file, const std::string& name) {
  (void)file;
  textures.push_back(name);
  return {};
}

Result<void> RecordingHost::saveImage(std::string_view name) {
  images.emplace_back(name);
  return {};
}

Result<void> RecordingHost::accumulateJitterPass(int pass, int count) {
  passes.emplace_back(pass, count);
  return {};
}

Result<void> RecordingHost::tv(const TvRequest& request) {
  tvRequests.push_back(request);
  return fail(Errc::kUnavailable, "no movie player in the test host");
}

Program parse(std::string_view text) { return parseScript(text, "test.mdl"); }

std::size_t Run::count(Severity severity, std::string_view needle) const {
  std::size_t n = 0;
  for (const Diagnostic& d : messages) {
    if (d.severity == severity && d.message.find(needle) != std::string::npos) ++n;
  }
  return n;
}

Run run(std::string_view text, std::size_t maxSteps) {
  Run r;
  Program program = parse(text);
  r.messages = program.diagnostics;
  Interpreter interpreter(std::move(program), ".");
  interpreter.setReporter([&r](const Diagnostic& d) { r.messages.push_back(d); });
  for (std::size_t i = 0; i < maxSteps; ++i) {
    const StepResult step = interpreter.step(r.show, r.host);
    r.steps.push_back(step);
    if (step.stop != StepStop::kDraw && step.stop != StepStop::kBudget) break;
    r.show.advanceFrame();
  }
  r.object = interpreter.objectSource();
  return r;
}

}  // namespace basalt::script::test
