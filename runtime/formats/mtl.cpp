// Wavefront material libraries: the statements Basalt uses (newmtl, Ka, Kd, Ks, Ke, Ns, d, Tr,
// map_Kd, map_bump/bump, refl, map_d) with the texture options real exporters write; every other
// statement is counted and reported once per file.

#include "runtime/formats/mtl.h"

#include <cmath>
#include <optional>

#include <fmt/format.h>

namespace basalt::formats {

namespace {

struct OptionSpec {
  std::string_view name;
  int minArgs;
  int maxArgs;
};

// Texture options of the MTL specification and common extensions, with their argument counts.
constexpr OptionSpec kTextureOptions[] = {
    {"-blendu", 1, 1},  {"-blendv", 1, 1}, {"-boost", 1, 1},      {"-mm", 2, 2},    {"-o", 1, 3},
    {"-s", 1, 3},       {"-t", 1, 3},      {"-texres", 1, 1},     {"-clamp", 1, 1}, {"-bm", 1, 1},
    {"-imfchan", 1, 1}, {"-type", 1, 1},   {"-colorspace", 1, 1}, {"-cc", 1, 1},
};

struct TokenSpan {
  std::string_view text;
  std::size_t offset;  // in the line
};

std::vector<TokenSpan> tokensWithOffsets(std::string_view line, std::size_t from) {
  std::vector<TokenSpan> out;
  std::size_t i = from;
  while (i < line.size()) {
    while (i < line.size() && (isBlank(line[i]) || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i]) && line[i] != '\r') ++i;
    if (i > start) out.push_back({line.substr(start, i - start), start});
  }
  return out;
}

class MtlParser {
 public:
  MtlParser(const std::filesystem::path& folder, const std::vector<std::filesystem::path>& searchPaths,
            Diagnostics& diagnostics)
      : folder_(folder), searchPaths_(searchPaths), d_(diagnostics) {}

  std::vector<runtime::Material> parse(std::string_view text) {
    LineReader lines(text);
    while (auto raw = lines.next()) {
      line_ = *raw;
      lineNumber_ = lines.number();
      std::string_view content = line_;
      if (const auto hash = content.find('#'); hash != std::string_view::npos) content = content.substr(0, hash);
      const std::size_t keyStart = firstNonBlank(content);
      if (keyStart >= content.size()) continue;
      std::size_t keyEnd = keyStart;
      while (keyEnd < content.size() && !isBlank(content[keyEnd]) && content[keyEnd] != '\r') ++keyEnd;
      const std::string_view keyword = content.substr(keyStart, keyEnd - keyStart);
      statement(keyword, content, keyEnd);
    }
    finishMaterial();
    return std::move(materials_);
  }

 private:
  static std::size_t firstNonBlank(std::string_view s) {
    std::size_t i = 0;
    while (i < s.size() && (isBlank(s[i]) || s[i] == '\r')) ++i;
    return i;
  }

  std::uint32_t column(std::size_t offset) const { return static_cast<std::uint32_t>(offset) + 1; }

  void statement(std::string_view keyword, std::string_view content, std::size_t argsAt) {
    if (keyword == "newmtl") {
      finishMaterial();
      current_ = runtime::Material{};
      current_->name = normaliseName(content.substr(argsAt));
      hasD_ = false;
      return;
    }
    if (!current_) {
      d_.warn(lineNumber_, column(firstNonBlank(content)),
              fmt::format("'{}' comes before any 'newmtl'; skipped", keyword));
      return;
    }
    runtime::Material& m = *current_;
    if (keyword == "Ka" || keyword == "Kd" || keyword == "Ks" || keyword == "Ke") {
      auto c = colour(content, argsAt, keyword);
      if (!c) return;
      if (keyword == "Ka") m.ambient = *c;
      if (keyword == "Kd") m.diffuse = *c;
      if (keyword == "Ks") m.specular = *c;
      if (keyword == "Ke") m.emissive = *c;
    } else if (keyword == "Ns") {
      if (auto v = number(content, argsAt, keyword)) m.shininess = *v;
    } else if (keyword == "d") {
      // "d -halo 0.5" is a rare variant: the factor follows the option.
      std::size_t at = argsAt;
      auto tokens = tokensWithOffsets(content, argsAt);
      if (!tokens.empty() && tokens[0].text == "-halo") at = tokens[0].offset + tokens[0].text.size();
      if (auto v = number(content, at, keyword)) {
        m.opacity = *v;
        hasD_ = true;
      }
    } else if (keyword == "Tr") {
      // Tr is transparency (1 - d); where both are given, d wins whatever the order.
      if (auto v = number(content, argsAt, keyword)) {
        if (!hasD_) m.opacity = 1.0f - *v;
      }
    } else if (keyword == "map_Kd") {
      texture(content, argsAt, keyword, m.diffuseMap);
    } else if (keyword == "map_bump" || keyword == "bump" || keyword == "map_Bump") {
      texture(content, argsAt, keyword, m.bumpMap);
    } else if (keyword == "refl" || keyword == "map_refl") {
      texture(content, argsAt, keyword, m.reflectionMap);
    } else if (keyword == "map_d") {
      texture(content, argsAt, keyword, m.alphaMap);
    } else {
      d_.ignored(keyword, lineNumber_);
    }
  }

  void finishMaterial() {
    if (!current_) return;
    for (const runtime::Material& existing : materials_) {
      if (existing.name == current_->name) {
        d_.warn(lineNumber_, 0,
                fmt::format("material '{}' is defined twice; the first definition is used", current_->name));
        current_.reset();
        return;
      }
    }
    if (materials_.size() >= 1u << 16) {
      d_.warn(lineNumber_, 0, "more than 65536 materials; the rest are skipped");
      current_.reset();
      return;
    }
    materials_.push_back(std::move(*current_));
    current_.reset();
  }

  std::optional<float> number(std::string_view content, std::size_t at, std::string_view keyword) {
    auto tokens = tokensWithOffsets(content, at);
    if (tokens.empty()) {
      d_.warn(lineNumber_, column(content.size()), fmt::format("'{}' needs a number; skipped", keyword));
      return std::nullopt;
    }
    float v = 0;
    if (!parseFloat(tokens[0].text, v) || !std::isfinite(v)) {
      d_.warn(lineNumber_, column(tokens[0].offset),
              fmt::format("'{}' is not a finite number; '{}' skipped", tokens[0].text, keyword));
      return std::nullopt;
    }
    return v;
  }

  std::optional<runtime::Color3> colour(std::string_view content, std::size_t at, std::string_view keyword) {
    auto tokens = tokensWithOffsets(content, at);
    if (!tokens.empty() && (tokens[0].text == "spectral" || tokens[0].text == "xyz")) {
      d_.warn(lineNumber_, column(tokens[0].offset),
              fmt::format("'{} {}' colours are not supported; give r g b instead; skipped", keyword, tokens[0].text));
      return std::nullopt;
    }
    if (tokens.empty()) {
      d_.warn(lineNumber_, column(content.size()), fmt::format("'{}' needs r g b; skipped", keyword));
      return std::nullopt;
    }
    float v[3] = {0, 0, 0};
    const std::size_t count = std::min<std::size_t>(tokens.size(), 3);
    for (std::size_t i = 0; i < count; ++i) {
      if (!parseFloat(tokens[i].text, v[i]) || !std::isfinite(v[i])) {
        d_.warn(lineNumber_, column(tokens[i].offset),
                fmt::format("'{}' is not a finite number; '{}' skipped", tokens[i].text, keyword));
        return std::nullopt;
      }
    }
    // "Ks 0": one value is a grey.
    if (count == 1) v[1] = v[2] = v[0];
    if (count == 2) {
      d_.warn(lineNumber_, column(tokens[1].offset), fmt::format("'{}' needs 1 or 3 values; skipped", keyword));
      return std::nullopt;
    }
    return runtime::Color3{v[0], v[1], v[2]};
  }

  void texture(std::string_view content, std::size_t at, std::string_view keyword, std::string& target) {
    auto tokens = tokensWithOffsets(content, at);
    // Options may come before or after the file name; the name is every token that is not an
    // option or an option's argument, and may contain blanks ("texture 01.png").
    std::size_t nameStart = std::string_view::npos, nameEnd = 0;
    for (std::size_t i = 0; i < tokens.size();) {
      const std::string_view t = tokens[i].text;
      // A quoted name ("my texture -old.png", as Basalt writes names that would not read back
      // otherwise) is one name: blanks, dashes and quotes inside are part of it. It ends at the
      // last quote on the line that is followed by a blank or the end of the line (a name may
      // hold '" ' itself, and there is no escape).
      if (t.front() == '"') {
        std::size_t close = std::string_view::npos;
        for (std::size_t q = content.find('"', tokens[i].offset + 1); q != std::string_view::npos;
             q = content.find('"', q + 1)) {
          if (q + 1 >= content.size() || isBlank(content[q + 1]) || content[q + 1] == '\r') close = q;
        }
        if (close != std::string_view::npos) {
          if (nameStart == std::string_view::npos) nameStart = tokens[i].offset;
          nameEnd = close + 1;
          while (i < tokens.size() && tokens[i].offset <= close) ++i;
          continue;
        }
      }
      const OptionSpec* spec = nullptr;
      if (t.size() > 1 && t[0] == '-') {
        for (const OptionSpec& o : kTextureOptions) {
          if (o.name == t) spec = &o;
        }
        float probe = 0;
        if (!spec && !parseFloat(t, probe)) {
          d_.ignored(fmt::format("{} {}", keyword, t), lineNumber_);
          ++i;
          continue;
        }
      }
      if (spec) {
        d_.ignored(fmt::format("{} {}", keyword, t), lineNumber_);
        ++i;
        int taken = 0;
        while (i < tokens.size() && taken < spec->maxArgs) {
          float probe = 0;
          const bool numeric = parseFloat(tokens[i].text, probe);
          // Options with numeric arguments stop at the first word; the others take words.
          if (taken >= spec->minArgs && !numeric) break;
          ++i;
          ++taken;
        }
        continue;
      }
      if (nameStart == std::string_view::npos) nameStart = tokens[i].offset;
      nameEnd = tokens[i].offset + t.size();
      ++i;
    }
    if (nameStart == std::string_view::npos) {
      d_.warn(lineNumber_, column(content.size()), fmt::format("'{}' names no file; skipped", keyword));
      return;
    }
    const std::string_view name = content.substr(nameStart, nameEnd - nameStart);
    const ResolvedPath resolved = resolveReferencedFile(name, folder_, searchPaths_);
    if (!resolved.found) {
      d_.warn(lineNumber_, column(nameStart),
              fmt::format("texture '{}' was not found (looked for {}); the material keeps the name", name,
                          resolved.path.string()));
    }
    target = resolved.path.string();
  }

  const std::filesystem::path& folder_;
  const std::vector<std::filesystem::path>& searchPaths_;
  Diagnostics& d_;
  std::vector<runtime::Material> materials_;
  std::optional<runtime::Material> current_;
  bool hasD_ = false;
  std::string_view line_;
  std::uint32_t lineNumber_ = 0;
};

std::string formatFloat(float v) { return fmt::format("{}", v); }

std::string formatColour(const runtime::Color3& c) {
  return fmt::format("{} {} {}", formatFloat(c.r), formatFloat(c.g), formatFloat(c.b));
}

}  // namespace

std::vector<runtime::Material> parseMtl(std::string_view text, const std::filesystem::path& folder,
                                        const std::vector<std::filesystem::path>& searchPaths,
                                        Diagnostics& diagnostics) {
  MtlParser parser(folder, searchPaths, diagnostics);
  return parser.parse(text);
}

Result<std::vector<runtime::Material>> readMtlFile(const std::filesystem::path& path, const LoadOptions& options,
                                                   std::vector<Diagnostic>& warnings) {
  auto bytes = readFileBytes(path, options.limits.maxFileBytes);
  if (!bytes) return std::unexpected(bytes.error());
  Diagnostics diagnostics(path.string(), options.limits.maxWarnings, options.logWarnings);
  auto text = decodeText(std::move(*bytes), diagnostics);
  if (!text) return std::unexpected(text.error());
  auto materials = parseMtl(*text, path.parent_path(), options.searchPaths, diagnostics);
  for (Diagnostic& d : diagnostics.finish()) warnings.push_back(std::move(d));
  return materials;
}

namespace {

/// A map's file name as an MTL line can carry it: quoted when, as it stands, it would read back
/// as another name (blanks at either end, a word the reader would take for an option, quotes).
std::string mapReference(const std::filesystem::path& target, const std::filesystem::path& folder) {
  std::string name = relativeReference(target, folder);
  bool quote = !name.empty() && (isBlank(name.front()) || isBlank(name.back()) || name.front() == '"');
  for (std::size_t i = 0; i < name.size() && !quote; ++i) {
    quote = name[i] == '-' && (i == 0 || isBlank(name[i - 1]));
  }
  return quote ? '"' + name + '"' : name;
}

}  // namespace

std::string formatMtl(const std::vector<runtime::Material>& materials, const std::filesystem::path& folder) {
  std::string out = "# Material library written by Basalt\n";
  for (const runtime::Material& m : materials) {
    out += fmt::format("\nnewmtl {}\n", m.name);
    out += fmt::format("Ka {}\nKd {}\nKs {}\n", formatColour(m.ambient), formatColour(m.diffuse),
                       formatColour(m.specular));
    if (m.emissive != runtime::Color3{0, 0, 0}) out += fmt::format("Ke {}\n", formatColour(m.emissive));
    out += fmt::format("Ns {}\nd {}\n", formatFloat(m.shininess), formatFloat(m.opacity));
    if (!m.diffuseMap.empty()) out += fmt::format("map_Kd {}\n", mapReference(m.diffuseMap, folder));
    if (!m.bumpMap.empty()) out += fmt::format("map_bump {}\n", mapReference(m.bumpMap, folder));
    if (!m.reflectionMap.empty()) out += fmt::format("refl {}\n", mapReference(m.reflectionMap, folder));
    if (!m.alphaMap.empty()) out += fmt::format("map_d {}\n", mapReference(m.alphaMap, folder));
  }
  return out;
}

}  // namespace basalt::formats
