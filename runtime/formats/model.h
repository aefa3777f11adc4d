#pragma once

/// \file
/// \brief Models from files and into the Show: Wavefront OBJ with MTL materials, the thesis'
/// Extended OBJ (objects with parents, instances, placement and texture maps), and OFF. This is
/// the API the `.mdl` interpreter and the kiosk call:
///
///   auto model = formats::loadModel("chair.obj");            // parse, with warnings
///   if (!model) report(model.error());                        // file:line:column: what is wrong
///   formats::replaceObject(show, *model);                     // LAVA `load_object`
///   formats::saveObject(show, "out.obj");                     // LAVA "Save Object"
///
/// Rule for partly bad files (runtime/formats/README.md): a statement that is wrong is
/// skipped with a warning that says where and what was skipped, and the rest loads; the whole
/// file is rejected when it cannot be read or decoded, goes over a cap in Limits, or leaves
/// nothing to draw although it had elements.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/formats/text.h"
#include "runtime/math.h"
#include "runtime/show/mesh.h"
#include "runtime/show/show.h"

namespace basalt::formats {

/// \brief One object of a model: an Extended OBJ `o` (or the whole file for plain OBJ and OFF)
/// with its placement relative to its parent (thesis §4.2.7-4.2.9).
struct ModelObject {
  std::string name;
  std::string parent;         ///< `parent`: the object this one is placed relative to ("" = none)
  std::string instanceOf;     ///< `instanceof`: the object whose geometry this one shares ("" = own)
  Vec3 position{0, 0, 0};     ///< `position x y z`
  Vec3 rotation{0, 0, 0};     ///< `rotation x y z`: degrees about X, then Y, then Z
  Vec3 scale{1, 1, 1};        ///< `scale s` or `scale x y z`
  std::string colorMap;       ///< `usemap file color`, resolved against the model's folder
  std::string reflectionMap;  ///< `usemap file reflect`
  std::string bumpMap;        ///< `usemap file bump`
  /// The geometry: groups and materials are its parts. Null for an instance or a pure transform.
  std::shared_ptr<const runtime::Mesh> mesh;
  std::uint32_t line = 0;  ///< where the object starts in its file (0 = the file's start)

  /// \brief translation * rotation (X, then Y, then Z) * scale.
  [[nodiscard]] Mat4 localTransform() const;
  friend bool operator==(const ModelObject& a, const ModelObject& b);
};

enum class ModelFormat : std::uint8_t { kObj, kOff };

/// \brief What a model file holds, ready to put into a Show.
struct LoadedModel {
  std::filesystem::path path;
  ModelFormat format = ModelFormat::kObj;
  /// The file used Extended OBJ statements (parent, instanceof, position, rotation, scale,
  /// usemap, vc).
  bool extended = false;
  std::vector<ModelObject> objects;
  std::vector<Diagnostic> warnings;  ///< what was skipped or guessed, with file:line:column
};

/// \brief Totals over a model's meshes (instances counted once).
struct ModelCounts {
  std::size_t objects = 0;
  std::size_t vertices = 0;  ///< after de-duplication of v/vt/vn combinations
  std::size_t triangles = 0;
  std::size_t facets = 0;  ///< polygons before triangulation
  std::size_t lineSegments = 0;
  std::size_t points = 0;
  std::size_t parts = 0;      ///< mesh parts (a group split by material counts once per material)
  std::size_t materials = 0;  ///< distinct material names
};
ModelCounts countModel(const LoadedModel& model);

/// \brief Reads a model file: `.obj` (plain or Extended) or `.off`; other names, and files
/// without an extension, are recognised by their content. MTL libraries named by `mtllib` are
/// read from the model's folder and `options.searchPaths`.
[[nodiscard]] Result<LoadedModel> loadModel(const std::filesystem::path& path, const LoadOptions& options = {});

/// \brief Parses OBJ text already in memory (no material libraries are read; `mtllib` lines are
/// reported as not loaded). `name` is what messages call the file; `folder` resolves `usemap`.
[[nodiscard]] Result<LoadedModel> parseObjText(std::string_view text, const std::string& name,
                                               const std::filesystem::path& folder, const LoadOptions& options);
/// \brief Parses OFF text already in memory.
[[nodiscard]] Result<LoadedModel> parseOffText(std::string_view text, const std::string& name,
                                               const LoadOptions& options);

/// \brief LAVA `load_object`: clears the Show (every attribute back to its default, as LAVA does
/// whenever an object is loaded), then adds the model's objects as scene nodes with their
/// parents and shared instances, names the textures of parts (material `map_Kd`, else the
/// object's `usemap` colour map) and sets the parts' surface attributes from their materials.
[[nodiscard]] Result<void> replaceObject(runtime::Show& show, const LoadedModel& model);

/// \brief Adds models to a Show without clearing it, as a scene imports them. Parents and
/// instances are looked up by object name among all the given models and the nodes already in
/// the Show; parts without a material take `materialState` when it is given (the scene's
/// material state in force at the import). Problems (an unknown parent, a cycle) are warnings:
/// the object is placed at the root. Returns the node id of each object, models in order.
///
/// An instance (`instanceof`) shares its original's geometry but not its parts: its parts are
/// parts of its own, named after it (the original's part named after the original becomes the
/// instance's name, any other part `instance/part`), so that its material and attributes never
/// repaint the original (thesis §4.2.9: instances share vertex and face data only).
struct ModelImport {
  const LoadedModel* model = nullptr;
  const runtime::Material* materialState = nullptr;  ///< null: parts keep their own or the default
  /// The state is a scene's (thesis §4.2.4, OpenGL's material): applied with applySceneMaterial.
  bool sceneMaterial = false;
};
std::vector<runtime::NodeId> addModels(runtime::Show& show, const std::vector<ModelImport>& imports,
                                       std::vector<Diagnostic>& warnings);

/// \brief The surface attributes a material stands for in LAVA's model (XGL lighting): colour
/// Kd, ambient and specular as reflectance factors, Ks as the specular colour, Ns as the
/// power, 1 - d as transparency; also the line and marker colour (as `obj_colors.part_color`).
void applyMaterial(runtime::Show& show, runtime::PartId part, const runtime::Material& material);

/// \brief A scene's material state exactly (thesis §4.2.4, E.5): applyMaterial's colour,
/// diffuse and specular, with the ambient colour as the part's own ambient reflectance (ka 1),
/// the emission, and the shininess as the specular power.
void applySceneMaterial(runtime::Show& show, runtime::PartId part, const runtime::Material& material);

// ---- Writing ---------------------------------------------------------------------------------

/// \brief How `writeObj` writes.
struct ObjWriteOptions {
  /// Extended OBJ: objects keep their own coordinates with `o`, `parent`, `instanceof`,
  /// `position`, `rotation`, `scale` and `usemap`. Plain OBJ (LAVA "Save Object"): every
  /// object's geometry in scene coordinates, instances written out in full, readable anywhere.
  bool extended = true;
  /// Name of the material library written beside the model ("" = the model's name + ".mtl";
  /// no library is written when no mesh has materials).
  std::string materialLibrary;
};

/// \brief OBJ text for a model; materials go to `mtlText` (empty when there are none).
/// Texture paths are written relative to `folder`.
std::string formatObj(const LoadedModel& model, const std::filesystem::path& folder, const ObjWriteOptions& options,
                      const std::string& mtlName, std::string& mtlText);

/// \brief Writes a model as OBJ (and its MTL beside it), each file to a temporary name first and
/// then renamed into place.
[[nodiscard]] Result<void> writeObj(const std::filesystem::path& path, const LoadedModel& model,
                                    const ObjWriteOptions& options = {});

/// \brief The Show's scene graph as a model: nodes become objects (named, parented, placed;
/// nodes sharing a mesh become instances of the first), ready for writeObj.
LoadedModel modelFromShow(const runtime::Show& show);

/// \brief LAVA "Save Object": the Show's current model as plain Wavefront OBJ (+ MTL), or as
/// Extended OBJ with `extended`.
[[nodiscard]] Result<void> saveObject(const runtime::Show& show, const std::filesystem::path& path,
                                      bool extended = false);

/// \brief Writes `text` to `path` through a temporary file in the same folder and a rename.
[[nodiscard]] Result<void> writeTextFile(const std::filesystem::path& path, std::string_view text);

}  // namespace basalt::formats
