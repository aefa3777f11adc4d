// Wavefront OBJ and the thesis' Extended OBJ (appendix C.2), read in one pass.
//
// Reads: v (with optional w, or r g b vertex colours), vt, vn, vc (Extended RGBA colours), f in
// every index form with negative (relative) indices, l, p, o, g, s, usemtl, mtllib, and the
// Extended statements parent, instanceof, position, rotation, scale and usemap. Polygons of any
// size are triangulated (concave ones by ear clipping); missing normals are generated (smooth
// within a smoothing group, flat otherwise). Each `o` starts an object (a scene node); `g`
// groups and `usemtl` materials split an object into parts.
// Limits: see formats::Limits. Vertices must be defined before the faces that use them.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <unordered_map>

#include <fmt/format.h>

#include "runtime/formats/model.h"
#include "runtime/formats/mtl.h"
#include "runtime/formats/obj_internal.h"
#include "runtime/formats/polygon.h"

namespace basalt::formats {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kGenerated = 0x80000000u;  // normal key bit: a generated normal's accumulator
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

enum ElementKind : std::uint32_t { kFaceElement = 0, kLineElement = 1, kPointElement = 2 };

struct Bucket {
  std::uint32_t group = 0;     // id in groupNames_
  std::uint32_t material = 0;  // id in materialNames_, kNone for no material
  std::vector<std::uint32_t> triangles, edges, lines, points, facetSizes;
};

struct VertexKey {
  std::uint32_t v, vt, n;
};

struct ObjectBuild {
  ModelObject object;
  bool explicitObject = false;
  std::uint32_t untypedMaps = 0;
  std::vector<Bucket> buckets;
  std::uint32_t currentBucket = kNone;
  std::vector<VertexKey> vertices;
  std::vector<std::uint32_t> nextSamePosition;  // chain of vertices sharing a position
  std::uint32_t maxOrderKey = 0;
  bool orderChanged = false;
  bool hasElements = false;
  bool hasNormals = false;    // some corner has a file or generated normal
  bool hasTexcoords = false;  // some corner has a texture coordinate
  std::uint32_t instanceLine = 0;
};

struct Corner {
  std::uint32_t v, vt, vn;
};

bool isCommentStart(std::string_view line, std::size_t i) { return line[i] == '#' && (i == 0 || isBlank(line[i - 1])); }

class ObjParser {
 public:
  ObjParser(std::string name, std::filesystem::path folder, const LoadOptions& options, bool readLibraries)
      : name_(std::move(name)),
        folder_(std::move(folder)),
        options_(options),
        limits_(options.limits),
        readLibraries_(readLibraries),
        d_(name_, options.limits.maxWarnings, options.logWarnings) {}

  /// Parses text it owns, and frees it before building the meshes.
  Result<LoadedModel> parseOwned(std::string text) {
    owned_ = std::move(text);
    return parseText(owned_);
  }

  Result<LoadedModel> parse(std::string_view bytesOrText, bool alreadyText) {
    std::string decoded;
    std::string_view text = bytesOrText;
    if (!alreadyText) {
      auto t = decodeText(std::string(bytesOrText), d_);
      if (!t) return std::unexpected(t.error());
      decoded = std::move(*t);
      text = decoded;
    }
    return parseText(text);
  }

 private:
  // ---- The line loop ---------------------------------------------------------------------------

  Result<LoadedModel> parseText(std::string_view text) {
    if (auto r = parseLines(text); !r) return std::unexpected(r.error());
    std::string().swap(owned_);  // the text is parsed: its memory goes before the meshes are built
    return finish();
  }

 public:
  /// Parses whole lines; called once for a text in memory, or chunk by chunk for a file.
  Result<void> parseLines(std::string_view text) {
    if (defaultObjectName_.empty()) {
      defaultObjectName_ = std::filesystem::path(name_).stem().string();
      if (defaultObjectName_.empty()) defaultObjectName_ = "object";
    }
    LineReader lines(text, LineReader::Continuation::kObjData, nextLine_);
    while (auto raw = lines.next()) {
      line_ = *raw;
      lineNumber_ = lines.number();
      if (auto r = statement(); !r) return std::unexpected(r.error());
    }
    nextLine_ = lines.nextNumber();
    line_ = {};
    return {};
  }
  [[nodiscard]] std::uint32_t nextLine() const { return nextLine_; }
  Diagnostics& diagnostics() { return d_; }

  /// Everything parsed: resolves materials, builds the meshes.
  Result<LoadedModel> finish() { return finishParse(); }

 private:
  std::uint32_t col(const char* at) const { return static_cast<std::uint32_t>(at - line_.data()) + 1; }
  std::uint32_t col(std::size_t offset) const { return static_cast<std::uint32_t>(offset) + 1; }
  std::string here(std::size_t offset) const { return d_.where(lineNumber_, col(offset)); }

  Result<void> statement() {
    std::string_view s = line_;
    std::size_t i = 0;
    while (i < s.size() && (isBlank(s[i]) || s[i] == '\r')) ++i;
    if (i >= s.size() || s[i] == '#') return {};
    // The statement ends at a comment ('#' after a blank) or the line's end.
    std::size_t end = i;
    while (end < s.size() && !isCommentStart(s, end)) ++end;
    std::size_t keyEnd = i;
    while (keyEnd < end && !isBlank(s[keyEnd]) && s[keyEnd] != '\r') ++keyEnd;
    const std::string_view key = s.substr(i, keyEnd - i);
    argsAt_ = keyEnd;
    argsEnd_ = end;
    keyAt_ = i;
    switch (key.size()) {
      case 1:
        switch (key[0]) {
          case 'v': return vertex();
          case 'f': return element(kFaceElement);
          case 'l': return element(kLineElement);
          case 'p': return element(kPointElement);
          case 'o': return startObject();
          case 'g': return group();
          case 's': return smoothing();
          default: break;
        }
        break;
      case 2:
        if (key == "vt") return texcoord();
        if (key == "vn") return normal();
        if (key == "vc") return vertexColour();
        if (key == "fo") return element(kFaceElement);  // old name of f
        break;
      default:
        if (key == "usemtl") return useMaterial();
        if (key == "mtllib") return materialLibrary();
        if (key == "parent") return objectName(current().object.parent, "parent");
        if (key == "instanceof") return instanceOf();
        if (key == "position") return placement(current().object.position, "position", false);
        if (key == "rotation") return placement(current().object.rotation, "rotation", false);
        if (key == "scale") return placement(current().object.scale, "scale", true);
        if (key == "usemap") return useMap();
        break;
    }
    d_.ignored(key, lineNumber_);
    return {};
  }

  // ---- Numbers --------------------------------------------------------------------------------

  /// Reads up to `max` floats from the arguments; returns how many, or -1 after a warning.
  int readFloats(float* out, int max, std::string_view what, std::size_t& badAt) {
    std::size_t i = argsAt_;
    int n = 0;
    const std::string_view s = line_.substr(0, argsEnd_);
    for (;;) {
      while (i < s.size() && (isBlank(s[i]) || s[i] == '\r')) ++i;
      if (i >= s.size()) break;
      if (n == max) {
        d_.warn(lineNumber_, col(i), fmt::format("'{}' has more than {} numbers; the rest are ignored", what, max));
        break;
      }
      std::size_t used = 0;
      float value = 0;
      const bool ok = scanFloat(s.substr(i), value, used);
      if (!ok || (i + used < s.size() && !isBlank(s[i + used]) && s[i + used] != '\r')) {
        std::size_t tokenEnd = i;
        while (tokenEnd < s.size() && !isBlank(s[tokenEnd])) ++tokenEnd;
        badAt = i;
        d_.warn(lineNumber_, col(i),
                fmt::format("'{}' is not a number; this {} is skipped", s.substr(i, tokenEnd - i), what));
        return -1;
      }
      out[n++] = value;
      i += used;
    }
    return n;
  }

  // ---- Vertex data ----------------------------------------------------------------------------

  Result<void> tooMany(std::string_view what, std::uint32_t cap) {
    return fail(Errc::kResourceExhausted,
                fmt::format("more than {} {}; the file is too large for Basalt's limits", cap, what), here(keyAt_));
  }

  Result<void> vertex() {
    if (positions_.size() >= limits_.maxVertices) return tooMany("vertices", limits_.maxVertices);
    float v[7];
    std::size_t bad = 0;
    const int n = readFloats(v, 7, "vertex", bad);
    Vec3 p{kNaN, kNaN, kNaN};
    if (n == 3 || n == 4 || n == 6 || n == 7) {
      if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
        p = {v[0], v[1], v[2]};
      } else {
        d_.warn(lineNumber_, col(argsAt_ + 1),
                fmt::format("vertex {} has a coordinate that is not a finite number; faces using it are skipped",
                            positions_.size() + 1));
      }
      if (n >= 6) {
        // "v x y z r g b" (MeshLab, ZBrush, Blender) and "v x y z r g b a": vertex colours.
        const Vec4 c{v[3], v[4], v[5], n == 7 ? v[6] : 1.0f};
        if (std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w)) {
          setColour(static_cast<std::uint32_t>(positions_.size()), c);
        } else {
          d_.warn(lineNumber_, col(argsAt_ + 1), "the vertex colour is not finite numbers; the vertex is white");
        }
      }
    } else if (n >= 0) {
      d_.warn(lineNumber_, col(argsAt_ + 1),
              fmt::format("a vertex needs 3 coordinates (or x y z r g b), not {}; faces using it are skipped", n));
    }
    positions_.push_back(p);
    return {};
  }

  void setColour(std::uint32_t index, const Vec4& c) {
    if (colours_.size() <= index) colours_.resize(std::size_t{index} + 1, Vec4{1, 1, 1, 1});
    colours_[index] = c;
  }

  Result<void> vertexColour() {
    extended_ = true;
    float v[4];
    std::size_t bad = 0;
    const int n = readFloats(v, 4, "vertex colour", bad);
    const std::uint32_t index = vcCount_++;
    if (index >= limits_.maxVertices) return tooMany("vertex colours", limits_.maxVertices);
    if (n < 0) return {};
    if (n != 3 && n != 4) {
      d_.warn(lineNumber_, col(argsAt_ + 1), fmt::format("'vc' needs r g b a, not {} numbers; skipped", n));
      return {};
    }
    if (n == 3) v[3] = 255.0f;
    // The thesis writes 0..255 integers; a value with a fraction means 0..1.
    const std::string_view args = line_.substr(argsAt_, argsEnd_ - argsAt_);
    const bool fractional = args.find_first_of(".eE") != std::string_view::npos;
    Vec4 c{v[0], v[1], v[2], v[3]};
    if (!fractional) c = {v[0] / 255.0f, v[1] / 255.0f, v[2] / 255.0f, v[3] / 255.0f};
    if (!(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w))) {
      d_.warn(lineNumber_, col(argsAt_ + 1), "'vc' has a value that is not a finite number; skipped");
      return {};
    }
    setColour(index, c);
    return {};
  }

  Result<void> texcoord() {
    if (texcoords_.size() >= limits_.maxVertices) return tooMany("texture coordinates", limits_.maxVertices);
    float v[3];
    std::size_t bad = 0;
    const int n = readFloats(v, 3, "texture coordinate", bad);
    Vec2 t{kNaN, kNaN};
    if (n >= 1) {
      if (n == 1) v[1] = 0;
      if (std::isfinite(v[0]) && std::isfinite(v[1])) {
        t = {v[0], v[1]};
      } else {
        d_.warn(lineNumber_, col(argsAt_ + 1),
                "a texture coordinate is not a finite number; faces using it are skipped");
      }
    } else if (n == 0) {
      d_.warn(lineNumber_, col(argsAt_ + 1), "'vt' needs a coordinate; faces using it are skipped");
    }
    texcoords_.push_back(t);
    return {};
  }

  Result<void> normal() {
    if (normals_.size() >= limits_.maxVertices) return tooMany("normals", limits_.maxVertices);
    float v[3];
    std::size_t bad = 0;
    const int n = readFloats(v, 3, "normal", bad);
    Vec3 nv{kNaN, kNaN, kNaN};
    if (n == 3) {
      if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
        nv = {v[0], v[1], v[2]};
      } else {
        d_.warn(lineNumber_, col(argsAt_ + 1), "a normal is not a finite number; faces using it are skipped");
      }
    } else if (n >= 0) {
      d_.warn(lineNumber_, col(argsAt_ + 1),
              fmt::format("a normal needs 3 numbers, not {}; faces using it are skipped", n));
    }
    normals_.push_back(nv);
    return {};
  }

  // ---- Objects, groups, materials ---------------------------------------------------------------

  ObjectBuild& current() {
    if (objects_.empty()) {
      objects_.emplace_back();
      objects_.back().object.name = defaultObjectName_;
      objects_.back().object.line = 0;
      beginObject();
    }
    return objects_.back();
  }

  void beginObject() {
    // The position chains belong to one object: clear the previous object's entries.
    if (objects_.size() >= 2) {
      for (const VertexKey& k : objects_[objects_.size() - 2].vertices) {
        if (k.v < headOf_.size()) headOf_[k.v] = kNone;
      }
    }
  }

  std::string restOfLine() const { return normaliseName(line_.substr(argsAt_, argsEnd_ - argsAt_)); }

  Result<void> startObject() {
    if (objects_.size() >= limits_.maxNames) return tooMany("objects", limits_.maxNames);
    // An implicit first object that holds nothing is dropped: the file's real objects start here.
    if (objects_.size() == 1 && !objects_[0].explicitObject && !objects_[0].hasElements &&
        objects_[0].object.parent.empty() && objects_[0].object.instanceOf.empty() && !placed_) {
      objects_.clear();
    }
    objects_.emplace_back();
    ObjectBuild& o = objects_.back();
    o.explicitObject = true;
    o.object.name = restOfLine();
    o.object.line = lineNumber_;
    if (o.object.name.empty()) o.object.name = fmt::format("{}.{}", defaultObjectName_, objects_.size());
    beginObject();
    currentGroup_ = kNone;  // a new object's faces are its own part until a 'g
    placed_ = false;
    return {};
  }

  Result<std::uint32_t> intern(std::unordered_map<std::string, std::uint32_t>& ids, std::vector<std::string>& names,
                               std::string name) {
    auto it = ids.find(name);
    if (it != ids.end()) return it->second;
    if (names.size() >= limits_.maxNames) return std::unexpected(tooMany("names", limits_.maxNames).error());
    const auto id = static_cast<std::uint32_t>(names.size());
    names.push_back(name);
    ids.emplace(std::move(name), id);
    return id;
  }

  Result<void> group() {
    std::string name = restOfLine();
    if (name.empty()) {
      currentGroup_ = kNone;
      return {};
    }
    auto id = intern(groupIds_, groupNames_, std::move(name));
    if (!id) return std::unexpected(id.error());
    currentGroup_ = *id;
    return {};
  }

  Result<void> smoothing() {
    const std::string arg = lowerAscii(restOfLine());
    std::int64_t value = 0;
    if (arg == "off" || arg.empty()) {
      smoothing_ = 0;
    } else if (parseInt(arg, value) && value >= 0) {
      if (value == 0) {
        smoothing_ = 0;
      } else {
        auto it = smoothingIds_.find(value);
        if (it == smoothingIds_.end()) {
          if (smoothingIds_.size() >= limits_.maxNames) return tooMany("smoothing groups", limits_.maxNames);
          it = smoothingIds_.emplace(value, static_cast<std::uint32_t>(smoothingIds_.size() + 1)).first;
        }
        smoothing_ = it->second;
      }
    } else {
      d_.warn(lineNumber_, col(argsAt_ + 1),
              fmt::format("'s {}' is not a smoothing group (a number or 'off'); the group is unchanged", arg));
    }
    return {};
  }

  Result<void> useMaterial() {
    std::string name = restOfLine();
    auto id = intern(materialIds_, materialNames_, std::move(name));
    if (!id) return std::unexpected(id.error());
    currentMaterial_ = *id;
    if (materialFirstLine_.size() <= *id) materialFirstLine_.resize(std::size_t{*id} + 1, lineNumber_);
    return {};
  }

  Result<void> materialLibrary() {
    const std::string_view args = trim(line_.substr(argsAt_, argsEnd_ - argsAt_));
    if (args.empty()) {
      d_.warn(lineNumber_, col(argsAt_), "'mtllib' names no file; skipped");
      return {};
    }
    if (!readLibraries_) {
      d_.warn(lineNumber_, col(argsAt_ + 1),
              fmt::format("material library '{}' was not read (the model was parsed from memory)", args));
      return {};
    }
    // A name with blanks ("mtl file.mtl") is tried whole first; otherwise each word is a file.
    std::vector<std::string_view> names;
    if (resolveReferencedFile(args, folder_, options_.searchPaths).found) {
      names.push_back(args);
    } else {
      names = splitBlanks(args);
    }
    for (std::string_view name : names) {
      const ResolvedPath resolved = resolveReferencedFile(name, folder_, options_.searchPaths);
      const std::size_t at = static_cast<std::size_t>(name.data() - line_.data());
      if (!resolved.found) {
        d_.warn(lineNumber_, col(at),
                fmt::format("material library '{}' was not found (looked for {}); its materials get defaults", name,
                            resolved.path.string()));
        continue;
      }
      if (std::find(libraries_.begin(), libraries_.end(), resolved.path) != libraries_.end()) continue;
      if (libraries_.size() >= 64) {
        d_.warn(lineNumber_, col(at), "more than 64 material libraries; the rest are skipped");
        break;
      }
      libraries_.push_back(resolved.path);
      std::vector<Diagnostic> libraryWarnings;
      auto materials = readMtlFile(resolved.path, options_, libraryWarnings);
      for (Diagnostic& w : libraryWarnings) libraryWarnings_.push_back(std::move(w));
      if (!materials) {
        d_.warn(lineNumber_, col(at),
                fmt::format("material library '{}' could not be read: {}", name, materials.error().describe()));
        continue;
      }
      for (runtime::Material& m : *materials) {
        if (materials_.contains(m.name)) continue;  // the first library that defines a name wins
        std::string key = m.name;
        materials_.emplace(std::move(key), std::move(m));
      }
    }
    return {};
  }

  Result<void> objectName(std::string& target, std::string_view what) {
    extended_ = true;
    std::string name = restOfLine();
    if (name.empty()) {
      d_.warn(lineNumber_, col(argsAt_), fmt::format("'{}' names no object; skipped", what));
      return {};
    }
    target = std::move(name);
    return {};
  }

  Result<void> instanceOf() {
    if (auto r = objectName(current().object.instanceOf, "instanceof"); !r) return r;
    current().instanceLine = lineNumber_;
    return {};
  }

  Result<void> placement(Vec3& target, std::string_view what, bool uniformAllowed) {
    extended_ = true;
    placed_ = true;
    current();  // the statement belongs to the current object, made here if there is none yet
    float v[3];
    std::size_t bad = 0;
    const int n = readFloats(v, 3, std::string(what), bad);
    if (n < 0) return {};
    if (n == 1 && uniformAllowed) {
      v[1] = v[2] = v[0];
    } else if (n != 3) {
      d_.warn(lineNumber_, col(argsAt_ + 1),
              fmt::format("'{}' needs {}3 numbers; skipped", what, uniformAllowed ? "1 or " : ""));
      return {};
    }
    if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) {
      d_.warn(lineNumber_, col(argsAt_ + 1), fmt::format("'{}' has a value that is not finite; skipped", what));
      return {};
    }
    target = {v[0], v[1], v[2]};
    return {};
  }

  Result<void> useMap() {
    extended_ = true;
    ObjectBuild& o = current();
    std::string_view args = trim(line_.substr(argsAt_, argsEnd_ - argsAt_));
    if (args.empty()) {
      d_.warn(lineNumber_, col(argsAt_), "'usemap' names no file; skipped");
      return {};
    }
    if (args == "off") {
      o.object.colorMap.clear();
      return {};
    }
    enum class Kind { kUnspecified, kColor, kReflect, kBump } kind = Kind::kUnspecified;
    const std::size_t lastBlank = args.find_last_of(" \t");
    if (lastBlank != std::string_view::npos) {
      const std::string word = lowerAscii(args.substr(lastBlank + 1));
      if (word == "color" || word == "colour") kind = Kind::kColor;
      if (word == "reflect" || word == "reflection") kind = Kind::kReflect;
      if (word == "bump") kind = Kind::kBump;
      if (kind != Kind::kUnspecified) args = trim(args.substr(0, lastBlank));
    }
    if (kind == Kind::kUnspecified) {
      // "first color, then reflect, then bump" (thesis C.2)
      const std::uint32_t nth = o.untypedMaps++;
      kind = nth == 0 ? Kind::kColor : nth == 1 ? Kind::kReflect : Kind::kBump;
      if (nth > 2) {
        d_.warn(lineNumber_, col(argsAt_ + 1),
                "more than three untyped 'usemap' lines; this one replaces the bump map");
      }
    }
    const ResolvedPath resolved = resolveReferencedFile(args, folder_, options_.searchPaths);
    if (!resolved.found) {
      d_.warn(
          lineNumber_, col(argsAt_ + 1),
          fmt::format("texture '{}' was not found (looked for {}); the name is kept", args, resolved.path.string()));
    }
    std::string path = resolved.path.string();
    switch (kind) {
      case Kind::kColor:
      case Kind::kUnspecified: o.object.colorMap = std::move(path); break;
      case Kind::kReflect: o.object.reflectionMap = std::move(path); break;
      case Kind::kBump: o.object.bumpMap = std::move(path); break;
    }
    return {};
  }

  // ---- Elements ---------------------------------------------------------------------------------

  /// Parses one index; 0 when absent. Returns false on a malformed number.
  static bool parseIndex(std::string_view s, std::size_t& i, std::int64_t& value, bool& present) {
    present = false;
    bool negative = false;
    std::size_t j = i;
    if (j < s.size() && (s[j] == '-' || s[j] == '+')) {
      negative = s[j] == '-';
      ++j;
    }
    const std::size_t digitsStart = j;
    std::int64_t v = 0;
    while (j < s.size() && s[j] >= '0' && s[j] <= '9') {
      if (v < (std::int64_t{1} << 40)) v = v * 10 + (s[j] - '0');
      ++j;
    }
    if (j == digitsStart) {
      if (j != i) return false;  // a sign without digits
      return true;               // nothing here: absent
    }
    value = negative ? -v : v;
    present = true;
    i = j;
    return true;
  }

  /// Turns an OBJ index (1-based, or negative from the end) into a 0-based one; on failure
  /// `problem` says why.
  static bool resolveIndex(std::int64_t raw, std::size_t count, std::uint32_t& out, std::string_view what,
                           std::string& problem) {
    const std::int64_t index = raw > 0 ? raw - 1 : static_cast<std::int64_t>(count) + raw;
    if (raw == 0) {
      problem = fmt::format("{} index 0 is not valid (OBJ indices start at 1, or count back from -1)", what);
      return false;
    }
    if (index < 0 || index >= static_cast<std::int64_t>(count)) {
      problem = fmt::format("{} index {} is out of range ({} defined before this line)", what, raw, count);
      return false;
    }
    out = static_cast<std::uint32_t>(index);
    return true;
  }

  /// Warns that an element is skipped, and remembers the first such warning: a file whose
  /// elements are all bad is rejected with it.
  Result<void> skipElement(std::size_t at, std::string message) {
    if (!firstSkip_) firstSkip_ = Diagnostic{d_.where(lineNumber_, col(at)), message};
    d_.warn(lineNumber_, col(at), std::move(message));
    return {};
  }

  /// Warns that a corner lost an attribute: the first time in full, later ones are counted and
  /// summed up at the end (a file with a wrong index usually has it on every line).
  void attributeProblem(std::size_t at, const std::string& problem, std::string_view what) {
    if (attributeWarnedLine_ == lineNumber_) return;
    attributeWarnedLine_ = lineNumber_;
    if (attributeProblems_++ == 0) {
      d_.warn(lineNumber_, col(at), fmt::format("{}; the element is kept {}", problem, what));
    }
  }

  Result<void> element(ElementKind kind) {
    ObjectBuild& o = current();
    const std::string_view s = line_.substr(0, argsEnd_);
    corners_.clear();
    std::size_t i = argsAt_;
    const char* kindName = kind == kFaceElement ? "face" : kind == kLineElement ? "line" : "point";
    for (;;) {
      while (i < s.size() && (isBlank(s[i]) || s[i] == '\r')) ++i;
      if (i >= s.size()) break;
      const std::size_t at = i;
      std::int64_t raw[3] = {0, 0, 0};
      bool present[3] = {false, false, false};
      bool ok = parseIndex(s, i, raw[0], present[0]) && present[0];
      for (int k = 1; ok && k < 3 && i < s.size() && s[i] == '/'; ++k) {
        ++i;
        ok = parseIndex(s, i, raw[k], present[k]);
      }
      if (!ok || (i < s.size() && !isBlank(s[i]) && s[i] != '\r')) {
        std::size_t tokenEnd = at;
        while (tokenEnd < s.size() && !isBlank(s[tokenEnd])) ++tokenEnd;
        return skipElement(at, fmt::format("'{}' is not a vertex reference (v, v/vt, v//vn or v/vt/vn); the {} is "
                                           "skipped",
                                           s.substr(at, tokenEnd - at), kindName));
      }
      if (corners_.size() >= limits_.maxFaceCorners) {
        return skipElement(at,
                           fmt::format("a {} with more than {} corners is skipped", kindName, limits_.maxFaceCorners));
      }
      Corner c{kNone, kNone, kNone};
      std::string problem;
      if (!resolveIndex(raw[0], positions_.size(), c.v, "vertex", problem)) {
        return skipElement(at, fmt::format("{}; the {} is skipped", problem, kindName));
      }
      if (std::isnan(positions_[c.v].x)) {
        return skipElement(at, fmt::format("the {} uses vertex {}, which could not be read (see the warning on its "
                                           "line); skipped",
                                           kindName, c.v + 1));
      }
      // A bad texture coordinate or normal costs only that attribute: the corner keeps its
      // place, without a texture coordinate or with a generated normal.
      if (present[1] && (!resolveIndex(raw[1], texcoords_.size(), c.vt, "texture coordinate", problem) ||
                         std::isnan(texcoords_[c.vt].x))) {
        if (problem.empty()) problem = fmt::format("texture coordinate {} could not be read", c.vt + 1);
        c.vt = kNone;
        attributeProblem(at, problem, "without a texture coordinate");
      }
      problem.clear();
      if (present[2] &&
          (!resolveIndex(raw[2], normals_.size(), c.vn, "normal", problem) || std::isnan(normals_[c.vn].x))) {
        if (problem.empty()) problem = fmt::format("normal {} could not be read", c.vn + 1);
        c.vn = kNone;
        attributeProblem(at, problem, "with a generated normal");
      }
      if (kind != kFaceElement) c.vn = kNone;  // lines and points are not lit
      corners_.push_back(c);
    }
    const std::size_t needed = kind == kFaceElement ? 3 : kind == kLineElement ? 2 : 1;
    if (corners_.size() < needed) {
      return skipElement(keyAt_, fmt::format("a {} needs at least {} vertices, this one has {}; skipped", kindName,
                                             needed, corners_.size()));
    }
    if (elementCount_ >= limits_.maxElements) return tooMany("elements", limits_.maxElements);
    ++elementCount_;
    o.hasElements = true;
    Bucket& b = bucketFor(o, kind);
    switch (kind) {
      case kFaceElement: return addFace(o, b);
      case kLineElement:
        for (std::size_t k = 0; k + 1 < corners_.size(); ++k) {
          auto a = vertexFor(o, corners_[k], kNone);
          if (!a) return std::unexpected(a.error());
          auto c = vertexFor(o, corners_[k + 1], kNone);
          if (!c) return std::unexpected(c.error());
          b.lines.push_back(*a);
          b.lines.push_back(*c);
        }
        return {};
      case kPointElement:
        for (const Corner& c : corners_) {
          auto a = vertexFor(o, c, kNone);
          if (!a) return std::unexpected(a.error());
          b.points.push_back(*a);
        }
        return {};
    }
    return {};
  }

  Bucket& bucketFor(ObjectBuild& o, ElementKind kind) {
    std::uint32_t group = currentGroup_;
    if (group == kNone) {
      // Geometry outside any group is the object's own part, named after the object.
      auto id = intern(groupIds_, groupNames_, o.object.name);
      group = id ? *id : 0;
    }
    std::uint32_t index = o.currentBucket;
    if (index == kNone || o.buckets[index].group != group || o.buckets[index].material != currentMaterial_) {
      index = kNone;
      for (std::uint32_t k = 0; k < o.buckets.size(); ++k) {
        if (o.buckets[k].group == group && o.buckets[k].material == currentMaterial_) index = k;
      }
      if (index == kNone) {
        index = static_cast<std::uint32_t>(o.buckets.size());
        o.buckets.emplace_back();
        o.buckets.back().group = group;
        o.buckets.back().material = currentMaterial_;
      }
      o.currentBucket = index;
    }
    const std::uint32_t key = index * 3 + kind;
    if (key < o.maxOrderKey) o.orderChanged = true;
    o.maxOrderKey = std::max(o.maxOrderKey, key);
    return o.buckets[index];
  }

  /// The unified vertex for a corner; `generatedNormal` is the accumulator to use when the corner
  /// has no normal of its own (kNone for lines and points).
  Result<std::uint32_t> vertexFor(ObjectBuild& o, const Corner& c, std::uint32_t generatedNormal) {
    const std::uint32_t n = c.vn != kNone ? c.vn : (generatedNormal == kNone ? kNone : (kGenerated | generatedNormal));
    const bool flat = c.vn == kNone && generatedNormal != kNone && smoothing_ == 0;
    if (!flat) {
      if (c.v >= headOf_.size()) headOf_.resize(positions_.size(), kNone);
      for (std::uint32_t k = headOf_[c.v]; k != kNone; k = o.nextSamePosition[k]) {
        const VertexKey& key = o.vertices[k];
        if (key.vt == c.vt && key.n == n) return k;
      }
    }
    if (o.vertices.size() >= limits_.maxVertices) {
      return std::unexpected(tooMany("vertices after combining v/vt/vn", limits_.maxVertices).error());
    }
    const auto id = static_cast<std::uint32_t>(o.vertices.size());
    o.vertices.push_back({c.v, c.vt, n});
    if (flat) {
      o.nextSamePosition.push_back(kNone);
    } else {
      o.nextSamePosition.push_back(headOf_[c.v]);
      headOf_[c.v] = id;
    }
    if (n != kNone) o.hasNormals = true;
    if (c.vt != kNone) o.hasTexcoords = true;
    return id;
  }

  Result<void> addFace(ObjectBuild& o, Bucket& b) {
    const auto n = static_cast<std::uint32_t>(corners_.size());
    // Corners without a normal share the face's generated one: the face normal (flat) or a
    // smoothing-group accumulator per position (smooth).
    bool needsNormal = false;
    for (const Corner& c : corners_) needsNormal = needsNormal || c.vn == kNone;
    cornerPositions_.clear();
    bool needPositions = n > 3 || needsNormal;
    if (needPositions) {
      for (const Corner& c : corners_) cornerPositions_.push_back(positions_[c.v]);
    }
    Vec3 faceNormal{0, 0, 0};
    if (needsNormal) faceNormal = newellNormal(cornerPositions_);
    ids_.clear();
    for (const Corner& c : corners_) {
      std::uint32_t generated = kNone;
      if (c.vn == kNone) {
        if (smoothing_ == 0) {
          generated = static_cast<std::uint32_t>(accumulators_.size());
          accumulators_.push_back(faceNormal);
        } else {
          const std::uint64_t key = (std::uint64_t{c.v} << 32) | smoothing_;
          auto [it, inserted] = smoothAccumulator_.try_emplace(key, static_cast<std::uint32_t>(accumulators_.size()));
          if (inserted) accumulators_.push_back({0, 0, 0});
          accumulators_[it->second] += faceNormal;
          generated = it->second;
        }
        if (accumulators_.size() >= kGenerated) {
          return std::unexpected(tooMany("generated normals", kGenerated).error());
        }
      }
      auto id = vertexFor(o, c, generated);
      if (!id) return std::unexpected(id.error());
      ids_.push_back(*id);
    }
    if (n == 3) {
      b.triangles.insert(b.triangles.end(), {ids_[0], ids_[1], ids_[2]});
    } else {
      triangleCorners_.clear();
      if (!triangulatePolygon(cornerPositions_, triangleCorners_, limits_.triangulationBudget)) {
        d_.warn(
            lineNumber_, col(keyAt_),
            fmt::format("this {}-corner polygon is too tangled to triangulate exactly; the rest of it was fanned", n));
      }
      for (std::uint32_t t : triangleCorners_) b.triangles.push_back(ids_[t]);
    }
    for (std::uint32_t k = 0; k < n; ++k) {
      b.edges.push_back(ids_[k]);
      b.edges.push_back(ids_[(k + 1) % n]);
    }
    b.facetSizes.push_back(n);
    return {};
  }

  // ---- The end ----------------------------------------------------------------------------------

  Result<LoadedModel> finishParse() {
    LoadedModel model;
    model.format = ModelFormat::kObj;
    model.extended = extended_;
    if (attributeProblems_ > 1) {
      d_.warn(0, 0,
              fmt::format("{} more lines had texture coordinate or normal indices that are out of range or "
                          "unreadable; their elements were kept without them",
                          attributeProblems_ - 1));
    }
    if (vcCount_ > positions_.size()) {
      d_.warn(0, 0,
              fmt::format("{} 'vc' colours for {} vertices; the extra ones are unused", vcCount_, positions_.size()));
    }
    // Warn once about each material name no library defined.
    for (std::uint32_t id = 0; id < materialNames_.size(); ++id) {
      if (!materials_.contains(materialNames_[id])) {
        d_.warn(id < materialFirstLine_.size() ? materialFirstLine_[id] : 0, 0,
                fmt::format("material '{}' is not defined in any material library read; it gets default values",
                            materialNames_[id]));
      }
    }
    bool anyGeometry = false;
    for (ObjectBuild& o : objects_) anyGeometry = anyGeometry || o.hasElements;
    // A point cloud (vertices, no elements at all) is shown as points.
    if (!anyGeometry && elementCount_ == 0 && !firstSkip_ && !positions_.empty()) {
      ObjectBuild& o = current();
      Bucket& b = bucketFor(o, kPointElement);
      for (std::uint32_t v = 0; v < positions_.size(); ++v) {
        if (std::isnan(positions_[v].x)) continue;
        auto id = vertexFor(o, Corner{v, kNone, kNone}, kNone);
        if (!id) return std::unexpected(id.error());
        b.points.push_back(*id);
      }
      o.hasElements = !b.points.empty();
      anyGeometry = o.hasElements;
      if (anyGeometry) {
        d_.warn(0, 0,
                fmt::format("the file has {} vertices and no faces, lines or points; they are shown as points",
                            positions_.size()));
      }
    }
    bool anyInstance = false;
    for (const ObjectBuild& o : objects_) anyInstance = anyInstance || !o.object.instanceOf.empty();
    // Objects without geometry still mean something when they place or parent others (an
    // Extended OBJ hierarchy whose geometry comes from other files).
    bool anyTransformObject = false;
    for (const ObjectBuild& o : objects_) anyTransformObject = anyTransformObject || placesSomething(o.object);
    if (!anyGeometry && !anyInstance && !anyTransformObject) {
      if (firstSkip_) {
        return fail(Errc::kParse, firstSkip_->message + " (nothing else in the file could be drawn)",
                    firstSkip_->where);
      }
      {
        return fail(Errc::kParse,
                    positions_.empty() ? "the file has no vertices, faces, lines or points; is it an OBJ file?"
                                       : "none of the file's vertices could be read",
                    name_);
      }
    }
    std::size_t lastWithGeometry = objects_.size();
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      if (objects_[i].hasElements && objects_[i].object.instanceOf.empty()) lastWithGeometry = i;
    }
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      ObjectBuild& o = objects_[i];
      lastMesh_ = i == lastWithGeometry;
      if (!o.hasElements && !o.explicitObject && o.object.instanceOf.empty() && !placesSomething(o.object)) continue;
      if (o.hasElements && !o.object.instanceOf.empty()) {
        d_.warn(o.instanceLine, 0,
                fmt::format("object '{}' has geometry of its own and is an instance of '{}'; the shared geometry is "
                            "used and its own is ignored",
                            o.object.name, o.object.instanceOf));
        o.hasElements = false;
      }
      if (o.hasElements) o.object.mesh = buildMesh(o);
      model.objects.push_back(std::move(o.object));
    }
    objects_.clear();
    model.warnings = d_.finish();
    for (Diagnostic& w : libraryWarnings_) model.warnings.push_back(std::move(w));
    return model;
  }

  /// True for an object that means something without geometry: it is placed, parented or
  /// textured.
  static bool placesSomething(const ModelObject& m) {
    return !m.parent.empty() || m.position != Vec3{0, 0, 0} || m.rotation != Vec3{0, 0, 0} ||
           m.scale != Vec3{1, 1, 1} || !m.colorMap.empty() || !m.reflectionMap.empty() || !m.bumpMap.empty();
  }

  runtime::Material materialFor(std::uint32_t id) const {
    auto it = materials_.find(materialNames_[id]);
    if (it != materials_.end()) return it->second;
    runtime::Material m;
    m.name = materialNames_[id];
    return m;
  }

  std::shared_ptr<const runtime::Mesh> buildMesh(ObjectBuild& o) {
    auto mesh = std::make_shared<runtime::Mesh>();
    runtime::Mesh& m = *mesh;
    // Parts: the buckets in order of first use; materials in order of first use.
    std::vector<std::uint32_t> localMaterial(materialNames_.size(), kNone);
    std::size_t tri = 0, edge = 0, line = 0, point = 0, facets = 0;
    for (const Bucket& b : o.buckets) {
      tri += b.triangles.size();
      edge += b.edges.size();
      line += b.lines.size();
      point += b.points.size();
      facets += b.facetSizes.size();
    }
    const bool single = o.buckets.size() == 1;
    if (!single) {
      m.triangles.reserve(tri);
      m.edges.reserve(edge);
      m.lines.reserve(line);
      m.points.reserve(point);
      m.facetSizes.reserve(facets);
    }
    for (Bucket& b : o.buckets) {
      runtime::MeshPart part;
      part.name = groupNames_[b.group];
      if (b.material != kNone) {
        if (localMaterial[b.material] == kNone) {
          localMaterial[b.material] = static_cast<std::uint32_t>(m.materials.size());
          m.materials.push_back(materialFor(b.material));
        }
        part.material = static_cast<std::int32_t>(localMaterial[b.material]);
      }
      part.firstTriangleIndex = static_cast<std::uint32_t>(m.triangles.size());
      part.triangleIndexCount = static_cast<std::uint32_t>(b.triangles.size());
      part.firstEdgeIndex = static_cast<std::uint32_t>(m.edges.size());
      part.edgeIndexCount = static_cast<std::uint32_t>(b.edges.size());
      part.firstLineIndex = static_cast<std::uint32_t>(m.lines.size());
      part.lineIndexCount = static_cast<std::uint32_t>(b.lines.size());
      part.firstPointIndex = static_cast<std::uint32_t>(m.points.size());
      part.pointIndexCount = static_cast<std::uint32_t>(b.points.size());
      part.firstFacet = static_cast<std::uint32_t>(m.facetSizes.size());
      part.facetCount = static_cast<std::uint32_t>(b.facetSizes.size());
      if (single) {
        m.triangles = std::move(b.triangles);
        m.edges = std::move(b.edges);
        m.lines = std::move(b.lines);
        m.points = std::move(b.points);
        m.facetSizes = std::move(b.facetSizes);
      } else {
        m.triangles.insert(m.triangles.end(), b.triangles.begin(), b.triangles.end());
        m.edges.insert(m.edges.end(), b.edges.begin(), b.edges.end());
        m.lines.insert(m.lines.end(), b.lines.begin(), b.lines.end());
        m.points.insert(m.points.end(), b.points.begin(), b.points.end());
        m.facetSizes.insert(m.facetSizes.end(), b.facetSizes.begin(), b.facetSizes.end());
        b = Bucket{};
      }
      m.parts.push_back(std::move(part));
    }
    o.buckets.clear();

    // Canonical vertex order (first use in part order: polygon corners, line ends, points), so
    // that writing the mesh and reading it back gives the same mesh.
    std::vector<std::uint32_t> order;
    if (o.orderChanged) {
      std::vector<std::uint32_t> remap(o.vertices.size(), kNone);
      order.reserve(o.vertices.size());
      const auto visit = [&](std::uint32_t& index) {
        if (remap[index] == kNone) {
          remap[index] = static_cast<std::uint32_t>(order.size());
          order.push_back(index);
        }
      };
      for (const runtime::MeshPart& p : m.parts) {
        for (std::uint32_t k = 0; k < p.edgeIndexCount; k += 2) visit(m.edges[p.firstEdgeIndex + k]);
        for (std::uint32_t k = 0; k < p.lineIndexCount; ++k) visit(m.lines[p.firstLineIndex + k]);
        for (std::uint32_t k = 0; k < p.pointIndexCount; ++k) visit(m.points[p.firstPointIndex + k]);
      }
      for (auto* list : {&m.triangles, &m.edges, &m.lines, &m.points}) {
        for (std::uint32_t& index : *list) index = remap[index];
      }
    }
    const std::size_t count = o.vertices.size();
    const auto source = [&](std::size_t i) -> const VertexKey& { return o.vertices[order.empty() ? i : order[i]]; };
    // The last mesh built frees each raw array as soon as it has taken what it needs.
    const auto done = [this](auto& raw) {
      if (lastMesh_) std::remove_reference_t<decltype(raw)>().swap(raw);
    };
    m.positions.resize(count);
    for (std::size_t i = 0; i < count; ++i) m.positions[i] = positions_[source(i).v];
    done(positions_);
    done(headOf_);
    if (o.hasTexcoords) {
      m.texcoords.resize(count);
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t vt = source(i).vt;
        m.texcoords[i] = vt == kNone ? Vec2{0, 0} : texcoords_[vt];
      }
    }
    done(texcoords_);
    if (o.hasNormals) {
      m.normals.resize(count);
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t n = source(i).n;
        if (n == kNone) {
          m.normals[i] = {0, 0, 1};  // line and point vertices: not lit
        } else if (n & kGenerated) {
          const Vec3 sum = accumulators_[n & ~kGenerated];
          const float len = length(sum);
          m.normals[i] = len > 0 ? sum / len : Vec3{0, 0, 1};
        } else {
          m.normals[i] = normals_[n];
        }
      }
    }
    done(normals_);
    done(accumulators_);
    if (!colours_.empty()) {
      m.colors.resize(count);
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t v = source(i).v;
        m.colors[i] = v < colours_.size() ? colours_[v] : Vec4{1, 1, 1, 1};
      }
    }
    o.vertices.clear();
    o.vertices.shrink_to_fit();
    o.nextSamePosition.clear();
    o.nextSamePosition.shrink_to_fit();
    return mesh;
  }

  std::string name_;
  std::string owned_;  // the file's text when the parser owns it
  std::filesystem::path folder_;
  const LoadOptions& options_;
  const Limits& limits_;
  bool readLibraries_;
  Diagnostics d_;

  std::string_view line_;
  std::uint32_t lineNumber_ = 0;
  std::uint32_t nextLine_ = 1;
  std::size_t keyAt_ = 0, argsAt_ = 0, argsEnd_ = 0;

  std::vector<Vec3> positions_;
  std::vector<Vec2> texcoords_;
  std::vector<Vec3> normals_;
  std::vector<Vec4> colours_;
  std::uint32_t vcCount_ = 0;
  std::vector<std::uint32_t> headOf_;
  std::vector<Vec3> accumulators_;
  std::unordered_map<std::uint64_t, std::uint32_t> smoothAccumulator_;

  std::vector<ObjectBuild> objects_;
  std::string defaultObjectName_;
  bool placed_ = false;
  bool lastMesh_ = false;
  bool extended_ = false;
  std::optional<Diagnostic> firstSkip_;
  std::uint32_t attributeWarnedLine_ = 0;
  std::uint32_t attributeProblems_ = 0;
  std::uint32_t elementCount_ = 0;
  std::uint32_t currentGroup_ = kNone;
  std::uint32_t currentMaterial_ = kNone;
  std::uint32_t smoothing_ = 0;
  std::unordered_map<std::int64_t, std::uint32_t> smoothingIds_;
  std::unordered_map<std::string, std::uint32_t> groupIds_;
  std::vector<std::string> groupNames_;
  std::unordered_map<std::string, std::uint32_t> materialIds_;
  std::vector<std::string> materialNames_;
  std::vector<std::uint32_t> materialFirstLine_;
  std::unordered_map<std::string, runtime::Material> materials_;
  std::vector<std::filesystem::path> libraries_;
  std::vector<Diagnostic> libraryWarnings_;

  std::vector<Corner> corners_;
  std::vector<Vec3> cornerPositions_;
  std::vector<std::uint32_t> ids_;
  std::vector<std::uint32_t> triangleCorners_;
};

}  // namespace

namespace {

bool isLineEnd(char c) { return c == '\n' || c == '\r'; }

/// Line ends in `text` ("\r\n" is one, a lone "\r" is one).
std::uint32_t countLineEnds(std::string_view text) {
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n' || (text[i] == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n'))) ++n;
  }
  return n;
}

/// Where to cut a chunk so that it holds whole statements: after the last line end, but before
/// a trailing "\r" (its "\n" may be in the next chunk) and before lines ending in a backslash
/// (they continue in the next chunk). 0 when nothing can be parsed yet.
std::size_t wholeLines(std::string_view buffer) {
  std::size_t cut = buffer.find_last_of("\n\r");
  if (cut == std::string_view::npos) return 0;
  if (buffer[cut] == '\r' && cut + 1 == buffer.size()) {
    if (cut == 0) return 0;
    cut = buffer.find_last_of("\n\r", cut - 1);
    if (cut == std::string_view::npos) return 0;
  }
  ++cut;
  while (cut > 0) {
    // The last line before the cut, without its end.
    std::size_t end = cut;
    while (end > 0 && isLineEnd(buffer[end - 1])) --end;
    std::size_t start = end;
    while (start > 0 && !isLineEnd(buffer[start - 1])) --start;
    std::string_view line = buffer.substr(start, end - start);
    while (!line.empty() && isBlank(line.back())) line.remove_suffix(1);
    if (line.empty() || line.back() != '\\') break;
    cut = start;
  }
  return cut;
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

Result<LoadedModel> readObjStreamed(const std::filesystem::path& path, const LoadOptions& options, bool& fallback,
                                    std::size_t chunkBytes) {
  fallback = false;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || !std::filesystem::is_regular_file(path, ec)) {
    fallback = true;  // the whole-file reader says what is wrong
    return fail(Errc::kNotFound, "", path.string());
  }
  if (size > options.limits.maxFileBytes) {
    return fail(
        Errc::kResourceExhausted,
        fmt::format("the file has {} bytes, more than the limit of {} bytes", size, options.limits.maxFileBytes),
        path.string());
  }
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) {
    fallback = true;
    return fail(Errc::kIo, "", path.string());
  }
  // A look at the start: UTF-16 and OFF content go to the whole-file reader.
  std::string head(4096, '\0');
  head.resize(std::fread(head.data(), 1, head.size(), file.get()));
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(head[i]); };
  if (head.size() >= 2 && ((byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0xFF && byte(1) == 0xFE) ||
                           (head.size() >= 4 && (byte(0) == 0 || byte(1) == 0)))) {
    fallback = true;
    return fail(Errc::kUnsupported, "", path.string());
  }
  {
    std::string_view h = head;
    while (!h.empty() && (isBlank(h.front()) || isLineEnd(h.front()))) h.remove_prefix(1);
    if (h.starts_with("\xEF\xBB\xBF")) h.remove_prefix(3);
    const std::string_view word = h.substr(0, std::min(h.find_first_of(" \t\r\n"), h.size()));
    if (word.size() >= 3 && word.substr(word.size() - 3) == "OFF") {
      fallback = true;
      return fail(Errc::kUnsupported, "", path.string());
    }
  }
  if (std::fseek(file.get(), 0, SEEK_SET) != 0) return fail(Errc::kIo, "cannot seek back to the start", path.string());
  ObjParser parser(path.string(), path.parent_path(), options, true);
  std::string buffer;
  bool first = true, eof = false;
  chunkBytes = std::max<std::size_t>(chunkBytes, 1);
  while (true) {
    const std::size_t old = buffer.size();
    buffer.resize(old + chunkBytes);
    const std::size_t got = std::fread(buffer.data() + old, 1, chunkBytes, file.get());
    buffer.resize(old + got);
    if (got < chunkBytes) {
      if (std::ferror(file.get())) return fail(Errc::kIo, "reading the file failed", path.string());
      eof = true;
    }
    std::size_t fresh = old;
    if (first && buffer.size() >= 3 && buffer.compare(0, 3, "\xEF\xBB\xBF") == 0) {
      buffer.erase(0, 3);
      fresh = 0;
    }
    if (first && (buffer.size() >= 3 || eof)) first = false;
    if (const std::size_t zero = buffer.find('\0', fresh); zero != std::string::npos) {
      const std::string_view before(buffer.data(), zero);
      const std::size_t lineStart = before.find_last_of("\n\r");
      const std::size_t column = zero - (lineStart == std::string_view::npos ? 0 : lineStart + 1) + 1;
      return parseError(
          parser.diagnostics().where(parser.nextLine() + countLineEnds(before), static_cast<std::uint32_t>(column)),
          "this is not a text file (it has a zero byte here); check that the right file was named");
    }
    const std::size_t cut = eof ? buffer.size() : wholeLines(buffer);
    if (cut > 0) {
      if (auto r = parser.parseLines(std::string_view(buffer.data(), cut)); !r) return std::unexpected(r.error());
      buffer.erase(0, cut);
    }
    if (eof) break;
  }
  std::string().swap(buffer);
  auto model = parser.finish();
  if (model) model->path = path;
  return model;
}

Result<LoadedModel> parseObjText(std::string_view text, const std::string& name, const std::filesystem::path& folder,
                                 const LoadOptions& options) {
  ObjParser parser(name, folder, options, false);
  return parser.parse(text, false);
}

Result<LoadedModel> readObjFile(std::string text, const std::filesystem::path& path, const LoadOptions& options) {
  ObjParser parser(path.string(), path.parent_path(), options, true);
  auto model = parser.parseOwned(std::move(text));
  if (model) model->path = path;
  return model;
}

}  // namespace basalt::formats
