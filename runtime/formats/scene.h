#pragma once

/// \file
/// \brief Scene files (`.sce`, thesis appendix C.3 and §4.3.5) and height-map terrain (§4.6):
/// the viewport, projection, stereo eye spacing, background colour, image or skybox, fog, the
/// viewer's bounds, start and speeds, lights, and the models and terrains a scene imports with
/// the material state in force when each is imported. Read and written (the thesis never
/// finished writing them).
///
///   auto scene = formats::loadScene("museum.sce", options);   // reads, imports the models
///   formats::applyScene(show, *scene);                         // into the Show
///
/// Scenes load what is sound: a bad statement or a model that cannot be imported is a warning
/// naming file:line:column, and the rest of the scene loads.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/formats/model.h"
#include "runtime/formats/text.h"
#include "runtime/image.h"
#include "runtime/show/show.h"

namespace basalt::formats {

/// \brief The material state a scene applies to models imported after it (thesis E.5 defaults).
/// Colours are 0..1 (files hold 0..255).
struct SceneMaterial {
  runtime::Color3 emission{0, 0, 0};
  runtime::Color3 ambient{0.2f, 0.2f, 0.2f};
  runtime::Color3 diffuse{0.8f, 0.8f, 0.8f};
  runtime::Color3 specular{0, 0, 0};
  float shininess = 1.0f;
  friend bool operator==(const SceneMaterial&, const SceneMaterial&) = default;
  /// \brief As a material for applyMaterial.
  [[nodiscard]] runtime::Material toMaterial() const;
};

/// \brief The global ambient colour a scene's lights come with: OpenGL's default light-model
/// ambient (thesis §4.2.4 adds it, scaled by the material's ambient colour; a scene file has no
/// statement for it). applyScene puts it in light 0, an ambient light.
inline constexpr runtime::Color3 kSceneGlobalAmbient{0.2f, 0.2f, 0.2f};

enum class SceneFogFunction : std::uint8_t { kLinear, kExp, kExp2 };

struct SceneFog {
  float start = 0.0f;
  float end = 1.0f;
  float density = 1.0f;
  runtime::Color3 color{0, 0, 0};
  SceneFogFunction function = SceneFogFunction::kExp;
  friend bool operator==(const SceneFog&, const SceneFog&) = default;
};

/// \brief `light position[x,y,z,w] ambient[] diffuse[] specular[]`: w = 0 is a directional
/// light shining from (x, y, z) towards the origin, otherwise a point light at (x, y, z) / w.
struct SceneLight {
  Vec4 position{0, 0, 1, 0};
  runtime::Color3 ambient{0, 0, 0};
  runtime::Color3 diffuse{1, 1, 1};
  runtime::Color3 specular{1, 1, 1};
  friend bool operator==(const SceneLight&, const SceneLight&) = default;
};

/// \brief An `import`, `importdir` or `terrain` statement, in file order.
struct SceneSource {
  enum class Kind : std::uint8_t { kModel, kDirectory, kTerrain };
  Kind kind = Kind::kModel;
  std::string path;        ///< as written (relative to the scene's folder)
  SceneMaterial material;  ///< the material state in force at this statement
  float amplitude = 1.0f;  ///< terrain: height of the brightest pixel
  Vec3 position{0, 0, 0};  ///< terrain: where its first pixel is
  std::uint32_t line = 0;  ///< where it is in the scene file (not compared)
  friend bool operator==(const SceneSource& a, const SceneSource& b) {
    return a.kind == b.kind && a.path == b.path && a.material == b.material && a.amplitude == b.amplitude &&
           a.position == b.position;
  }
};

/// \brief Everything a `.sce` file says, as it says it (defaults from the thesis).
struct SceneDescription {
  std::optional<std::array<std::int32_t, 4>> viewport;  ///< x, y, width, height
  float fieldOfView = 60.0f;
  float nearClip = 0.1f;
  float farClip = 1000.0f;
  float eyeSpacing = 0.04f;
  runtime::Color3 background{0, 0, 0};
  std::string backgroundImage;  ///< `background file`
  std::string skybox;           ///< `skybox file`: six views in a 3 x 2 image
  std::optional<SceneFog> fog;
  Vec3 mapMin{-1000, -1000, -1000};
  Vec3 mapMax{1000, 1000, 1000};
  Vec3 position{0, 0, 0};  ///< the viewer's start
  Vec3 rotation{0, 0, 0};  ///< degrees
  float positionChange = 25.0f;
  float rotationChange = 0.25f;
  std::vector<SceneLight> lights;
  std::vector<SceneSource> sources;
  SceneMaterial finalMaterial;  ///< the material state at the end of the file
  friend bool operator==(const SceneDescription&, const SceneDescription&) = default;
};

/// \brief Parses scene text; never fails on content (warnings say what was skipped), only on
/// undecodable text. `name` is what messages call the file.
[[nodiscard]] Result<SceneDescription> parseSceneText(std::string_view text, const std::string& name,
                                                      const LoadOptions& options, std::vector<Diagnostic>& warnings);

/// \brief A terrain built from a height map.
struct Terrain {
  std::shared_ptr<const runtime::Mesh> mesh;
  std::shared_ptr<const runtime::HeightField> heights;
  std::string name;
};

/// \brief A square grid with one vertex per pixel of `heightMap` (channel 0, or the luminance
/// of colour images), one unit apart in X (columns) and Z (rows), the brightest value at
/// `amplitude` in Y, the first pixel at `position`. Normals from the slopes; texture
/// coordinates span 0..1. Fails for images over Limits::maxTerrainSide pixels a side.
[[nodiscard]] Result<Terrain> makeTerrain(const Image& heightMap, float amplitude, const Vec3& position,
                                          const std::string& name, const Limits& limits);

/// \brief A scene with its models and terrains loaded.
struct LoadedScene {
  std::filesystem::path path;
  SceneDescription description;
  struct Import {
    LoadedModel model;
    SceneMaterial material;
  };
  std::vector<Import> models;  ///< every model imported, directories expanded, in order
  struct PlacedTerrain {
    Terrain terrain;
    SceneMaterial material;
  };
  std::vector<PlacedTerrain> terrains;
  std::vector<Diagnostic> warnings;  ///< the scene's and every imported file's
};

/// \brief Reads a scene and everything it imports. `options.decodeImage` decodes terrain height
/// maps (without it terrains are skipped with a warning). Fails only when the scene file itself
/// cannot be read.
[[nodiscard]] Result<LoadedScene> loadScene(const std::filesystem::path& path, const LoadOptions& options = {});

/// \brief Puts a scene into the Show: clears it (LAVA resets on a new load), imports the models
/// with their material states (applySceneMaterial), parents and instances across models
/// resolved by object name, adds the terrains, sets the lights (the scene's replace LAVA's
/// defaults: light 0 is the global ambient kSceneGlobalAmbient, the scene's lights follow with
/// their own ambient, diffuse and specular colours), background colour, image or skybox, fog,
/// the stereo eye spacing and the viewer, which draws the scene from its own camera in its own
/// units (`runtime::Framing::kScene`; useFitFraming turns that back to LAVA's view). Lights, fog
/// and eye spacing are in the scene's units (`runtime::Units::kScene`). Problems are appended
/// to `warnings`.
void applyScene(runtime::Show& show, const LoadedScene& scene, std::vector<Diagnostic>* warnings = nullptr);

/// \brief Frames a show as LAVA does (a manifest's `view = "fit"`): the world fitted to the
/// window from LAVA's eye, the viewer back at that eye (position and rotation 0) for walking.
void useFitFraming(runtime::Show& show);

/// \brief What a Show holds, as a scene description: background, fog, lights and viewer from the
/// Show; one `import` per model file its nodes came from (built-in geometry is not written).
SceneDescription describeScene(const runtime::Show& show, const std::filesystem::path& folder);

/// \brief Scene-file text for a description (the thesis' bracket syntax).
std::string formatScene(const SceneDescription& scene);
[[nodiscard]] Result<void> writeScene(const std::filesystem::path& path, const SceneDescription& scene);

}  // namespace basalt::formats
