// Object File Format (OFF) as Geomview defines it and files in the wild write it: the optional
// header keyword [ST][C][N][4][n]OFF (files without it start with the counts), counts that may
// share the header line, '#' comments, vertex normals (NOFF), vertex colours (COFF), texture
// coordinates (STOFF), homogeneous vertices (4OFF), and per-face colours (RGB[A], integers
// 0..255 or floats 0..1; a single colour-map index is ignored). Faces are 0-based and may be
// concave. Binary OFF is refused with a message.

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "runtime/formats/model.h"
#include "runtime/formats/obj_internal.h"
#include "runtime/formats/polygon.h"

namespace basalt::formats {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct OffHeader {
  bool texcoords = false, colours = false, normals = false, homogeneous = false;
  std::uint32_t dimension = 3;
};

/// Recognises "[ST][C][N][4][n]OFF".
bool parseKeyword(std::string_view word, OffHeader& h, bool& dimensionFollows) {
  dimensionFollows = false;
  if (word.size() < 3 || word.substr(word.size() - 3) != "OFF") return false;
  std::string_view prefix = word.substr(0, word.size() - 3);
  if (prefix.starts_with("ST")) {
    h.texcoords = true;
    prefix.remove_prefix(2);
  }
  if (prefix.starts_with("C")) {
    h.colours = true;
    prefix.remove_prefix(1);
  }
  if (prefix.starts_with("N")) {
    h.normals = true;
    prefix.remove_prefix(1);
  }
  if (prefix.starts_with("4")) {
    h.homogeneous = true;
    prefix.remove_prefix(1);
  }
  if (prefix.starts_with("n")) {
    dimensionFollows = true;
    prefix.remove_prefix(1);
  }
  return prefix.empty();
}

bool looksFractional(std::string_view token) { return token.find_first_of(".eE") != std::string_view::npos; }

/// A colour from 3 or 4 tokens: integers are 0..255, numbers with a fraction 0..1.
bool parseColour(const std::vector<std::string_view>& tokens, std::size_t first, Vec4& out) {
  float v[4] = {0, 0, 0, 1};
  const std::size_t count = tokens.size() - first;
  bool fractional = false;
  for (std::size_t i = 0; i < count; ++i) {
    if (!parseFloat(tokens[first + i], v[i]) || !std::isfinite(v[i])) return false;
    fractional = fractional || looksFractional(tokens[first + i]);
  }
  if (!fractional) {
    for (std::size_t i = 0; i < count; ++i) v[i] /= 255.0f;
  }
  out = {v[0], v[1], v[2], count == 4 ? v[3] : 1.0f};
  return true;
}

class OffParser {
 public:
  OffParser(std::string name, const LoadOptions& options)
      : name_(std::move(name)), limits_(options.limits), d_(name_, options.limits.maxWarnings, options.logWarnings) {}

  Result<LoadedModel> parse(std::string bytes) {
    auto text = decodeText(std::move(bytes), d_);
    if (!text) return std::unexpected(text.error());
    return parseText(*text);
  }

 private:
  /// The next line with content, split into tokens (comments removed).
  bool nextTokens(LineReader& lines, std::vector<std::string_view>& tokens, std::string_view& line) {
    while (auto raw = lines.next()) {
      line = *raw;
      std::string_view content = line;
      if (const auto hash = content.find('#'); hash != std::string_view::npos) content = content.substr(0, hash);
      tokens = splitBlanks(content);
      if (!tokens.empty()) return true;
    }
    return false;
  }

  std::uint32_t col(std::string_view line, std::string_view token) const {
    return static_cast<std::uint32_t>(token.data() - line.data()) + 1;
  }

  Result<LoadedModel> parseText(std::string_view text) {
    LineReader lines(text);
    std::vector<std::string_view> tokens;
    std::string_view line;
    if (!nextTokens(lines, tokens, line)) return parseError(name_, "the file is empty; an OFF file starts with 'OFF'");
    OffHeader h;
    std::size_t next = 0;
    bool dimensionFollows = false;
    if (parseKeyword(tokens[0], h, dimensionFollows)) {
      next = 1;
    } else {
      // Header-less: the counts come first ("many existing files lack this keyword").
      std::int64_t probe = 0;
      if (!parseInt(tokens[0], probe)) {
        return parseError(
            d_.where(lines.number(), col(line, tokens[0])),
            fmt::format("'{}' is neither an OFF keyword nor a vertex count; is this an OFF file?", tokens[0]));
      }
      d_.warn(lines.number(), 1, "the file has no 'OFF' keyword; it is read as OFF because it starts with counts");
    }
    auto needMore = [&]() -> bool {
      if (next < tokens.size()) return true;
      if (!nextTokens(lines, tokens, line)) return false;
      next = 0;
      return true;
    };
    if (next < tokens.size() && lowerAscii(tokens[next]) == "binary") {
      return parseError(d_.where(lines.number(), col(line, tokens[next])),
                        "binary OFF files are not supported; save the model as text OFF or OBJ");
    }
    if (dimensionFollows) {
      std::int64_t dim = 0;
      if (!needMore() || !parseInt(tokens[next], dim) || dim < 1 || dim > 16) {
        return parseError(d_.where(lines.number()), "nOFF needs its dimension (1 to 16) after the keyword");
      }
      h.dimension = static_cast<std::uint32_t>(dim);
      ++next;
    }
    if (h.homogeneous) ++h.dimension;
    // Counts: vertices, faces and (unused) edges, on the header line or the next.
    std::int64_t counts[3] = {0, 0, 0};
    int got = 0;
    std::uint32_t countLine = 0;
    while (got < 2 && needMore()) {
      countLine = lines.number();
      if (!parseInt(tokens[next], counts[got]) || counts[got] < 0) {
        return parseError(
            d_.where(lines.number(), col(line, tokens[next])),
            fmt::format("'{}' is not a count; the header needs the numbers of vertices and faces", tokens[next]));
      }
      ++got;
      ++next;
    }
    if (got < 2) return parseError(d_.where(lines.number()), "the file ends before the vertex and face counts");
    if (next < tokens.size()) ++next;  // the edge count, not used
    if (next < tokens.size()) {
      d_.warn(lines.number(), col(line, tokens[next]), "numbers after the counts are ignored");
    }
    next = tokens.size();
    if (counts[0] > limits_.maxVertices) {
      return fail(
          Errc::kResourceExhausted,
          fmt::format("the header promises {} vertices, more than the limit of {}", counts[0], limits_.maxVertices),
          d_.where(countLine));
    }
    if (counts[1] > limits_.maxElements) {
      return fail(
          Errc::kResourceExhausted,
          fmt::format("the header promises {} faces, more than the limit of {}", counts[1], limits_.maxElements),
          d_.where(countLine));
    }
    const auto vertexCount = static_cast<std::uint32_t>(counts[0]);
    const auto faceCount = static_cast<std::uint32_t>(counts[1]);

    // Vertices, one per line. Never reserve from the header alone: a lying header would allocate.
    const std::size_t reserve = std::min<std::size_t>(vertexCount, text.size() / 6 + 1);
    positions_.reserve(reserve);
    for (std::uint32_t v = 0; v < vertexCount; ++v) {
      if (next >= tokens.size() && !nextTokens(lines, tokens, line)) {
        return parseError(d_.where(lines.number() + 1),
                          fmt::format("the file ends after {} of the {} vertices its header promises", v, vertexCount));
      }
      next = tokens.size();  // the rest of this line is this vertex
      readVertex(h, tokens, line, lines.number());
    }

    // Faces, one per line, with an optional colour to the end of the line.
    for (std::uint32_t f = 0; f < faceCount; ++f) {
      if (!nextTokens(lines, tokens, line)) {
        d_.warn(lines.number(), 0,
                fmt::format("the header promises {} faces but the file has {}; the faces that are there are loaded",
                            faceCount, f));
        break;
      }
      readFace(tokens, line, lines.number());
    }
    if (nextTokens(lines, tokens, line)) {
      d_.warn(lines.number(), 1, "the file goes on after the faces its header promises; the rest is ignored");
    }
    return build(h);
  }

  void readVertex(const OffHeader& h, const std::vector<std::string_view>& tokens, std::string_view line,
                  std::uint32_t lineNumber) {
    const std::size_t needed = h.dimension + (h.normals ? 3 : 0);
    float values[16 + 3] = {};
    bool ok = tokens.size() >= needed;
    std::size_t badToken = tokens.size() > needed ? needed : 0;
    for (std::size_t i = 0; ok && i < needed; ++i) {
      if (!parseFloat(tokens[i], values[i]) || !std::isfinite(values[i])) {
        ok = false;
        badToken = i;
      }
    }
    Vec3 p{kNaN, kNaN, kNaN};
    if (ok) {
      p = {values[0], h.dimension > 1 ? values[1] : 0, h.dimension > 2 ? values[2] : 0};
      if (h.homogeneous) {
        const float w = values[h.dimension - 1];
        if (w != 0) p = p / w;
      }
      if (h.normals) {
        normals_.resize(positions_.size());
        normals_.push_back({values[h.dimension], values[h.dimension + 1], values[h.dimension + 2]});
      }
      if (h.colours && tokens.size() >= needed + 3) {
        std::vector<std::string_view> colour(tokens.begin() + static_cast<long>(needed),
                                             tokens.begin() + static_cast<long>(std::min(tokens.size(), needed + 4)));
        if (h.texcoords && tokens.size() >= needed + 5 && colour.size() == 4 && tokens.size() == needed + 5) {
          colour.pop_back();  // x y z r g b s t: the fourth value is s
        }
        Vec4 c{1, 1, 1, 1};
        if (parseColour(colour, 0, c)) {
          vertexColours_.resize(positions_.size(), Vec4{1, 1, 1, 1});
          vertexColours_.push_back(c);
        }
      }
      if (h.texcoords && tokens.size() >= needed + 2) {
        float s = 0, t = 0;
        if (parseFloat(tokens[tokens.size() - 2], s) && parseFloat(tokens[tokens.size() - 1], t) && std::isfinite(s) &&
            std::isfinite(t)) {
          texcoords_.resize(positions_.size());
          texcoords_.push_back({s, t});
        }
      }
    } else {
      const std::string_view where = badToken < tokens.size() ? tokens[badToken] : line;
      d_.warn(
          lineNumber, col(line, where),
          fmt::format("vertex {} needs {} finite numbers here; faces using it are skipped", positions_.size(), needed));
    }
    positions_.push_back(p);
  }

  void skipFace(std::uint32_t lineNumber, std::uint32_t column, std::string message) {
    if (!firstSkip_) firstSkip_ = Diagnostic{d_.where(lineNumber, column), message};
    d_.warn(lineNumber, column, std::move(message));
  }

  void readFace(const std::vector<std::string_view>& tokens, std::string_view line, std::uint32_t lineNumber) {
    std::int64_t n = 0;
    if (!parseInt(tokens[0], n) || n < 0) {
      skipFace(lineNumber, col(line, tokens[0]),
               fmt::format("'{}' is not a corner count; the face is skipped", tokens[0]));
      return;
    }
    if (n < 3) {
      skipFace(lineNumber, col(line, tokens[0]),
               fmt::format("a face needs at least 3 corners, this one has {}; skipped", n));
      return;
    }
    if (n > limits_.maxFaceCorners) {
      skipFace(lineNumber, col(line, tokens[0]),
               fmt::format("a face with {} corners is over the limit of {}; skipped", n, limits_.maxFaceCorners));
      return;
    }
    const auto corners = static_cast<std::size_t>(n);
    if (tokens.size() < corners + 1) {
      skipFace(lineNumber, col(line, tokens.back()),
               fmt::format("the face says it has {} corners but lists {}; skipped", n, tokens.size() - 1));
      return;
    }
    Face face;
    face.line = lineNumber;
    face.first = static_cast<std::uint32_t>(faceCorners_.size());
    face.count = static_cast<std::uint32_t>(corners);
    for (std::size_t i = 0; i < corners; ++i) {
      std::int64_t index = 0;
      const std::string_view t = tokens[i + 1];
      if (!parseInt(t, index) || index < 0 || index >= static_cast<std::int64_t>(positions_.size())) {
        faceCorners_.resize(face.first);
        skipFace(lineNumber, col(line, t),
                 fmt::format("'{}' is not a vertex index (0 to {}); the face is skipped", t,
                             positions_.empty() ? 0 : positions_.size() - 1));
        return;
      }
      if (std::isnan(positions_[static_cast<std::size_t>(index)].x)) {
        faceCorners_.resize(face.first);
        skipFace(lineNumber, col(line, t),
                 fmt::format("vertex {} could not be read (see its warning); the face is skipped", index));
        return;
      }
      faceCorners_.push_back(static_cast<std::uint32_t>(index));
    }
    const std::size_t extra = tokens.size() - corners - 1;
    if (extra == 3 || extra == 4) {
      Vec4 c;
      if (parseColour(tokens, corners + 1, c)) {
        face.colour = c;
        anyFaceColour_ = true;
      } else {
        d_.warn(lineNumber, col(line, tokens[corners + 1]), "the face's colour is not 3 or 4 numbers; it is ignored");
      }
    } else if (extra == 1) {
      d_.ignored("colour-map index", lineNumber);
    } else if (extra != 0) {
      d_.warn(lineNumber, col(line, tokens[corners + 1]),
              fmt::format("{} numbers after the face's corners are not a colour; they are ignored", extra));
    }
    if (faces_.size() >= limits_.maxElements) return;
    faces_.push_back(face);
  }

  Result<LoadedModel> build(const OffHeader& h) {
    if (faces_.empty()) {
      if (firstSkip_) {
        return fail(Errc::kParse, firstSkip_->message + " (nothing else in the file could be drawn)",
                    firstSkip_->where);
      }
      return parseError(name_, "the file has no faces to draw");
    }
    auto mesh = std::make_shared<runtime::Mesh>();
    runtime::Mesh& m = *mesh;
    const bool shared = h.normals && !anyFaceColour_;
    const bool haveColours = anyFaceColour_ || !vertexColours_.empty();
    const bool haveTexcoords = !texcoords_.empty();
    if (shared) {
      m.positions = positions_;
      for (Vec3& p : m.positions) {
        if (std::isnan(p.x)) p = {0, 0, 0};  // never referenced: faces using it were skipped
      }
      m.normals = normals_;
      m.normals.resize(m.positions.size(), Vec3{0, 0, 1});
      if (haveColours) {
        m.colors = vertexColours_;
        m.colors.resize(m.positions.size(), Vec4{1, 1, 1, 1});
      }
      if (haveTexcoords) {
        m.texcoords = texcoords_;
        m.texcoords.resize(m.positions.size(), Vec2{0, 0});
      }
    }
    std::vector<Vec3> corners;
    std::vector<std::uint32_t> tri;
    std::vector<std::uint32_t> ids;
    const Vec4 defaultGrey{0.666f, 0.666f, 0.666f, 1.0f};  // Geomview's default when some faces are coloured
    for (const Face& f : faces_) {
      corners.clear();
      for (std::uint32_t k = 0; k < f.count; ++k) corners.push_back(positions_[faceCorners_[f.first + k]]);
      ids.clear();
      if (shared) {
        for (std::uint32_t k = 0; k < f.count; ++k) ids.push_back(faceCorners_[f.first + k]);
      } else {
        // Flat faces: each face its own corners, with the face normal and the face colour.
        const Vec3 normal = normalize(newellNormal(corners));
        for (std::uint32_t k = 0; k < f.count; ++k) {
          const std::uint32_t v = faceCorners_[f.first + k];
          ids.push_back(static_cast<std::uint32_t>(m.positions.size()));
          m.positions.push_back(positions_[v]);
          m.normals.push_back(h.normals && v < normals_.size() ? normals_[v] : normal);
          if (haveColours) {
            m.colors.push_back(f.colour         ? *f.colour
                               : anyFaceColour_ ? defaultGrey
                                                : (v < vertexColours_.size() ? vertexColours_[v] : Vec4{1, 1, 1, 1}));
          }
          if (haveTexcoords) m.texcoords.push_back(v < texcoords_.size() ? texcoords_[v] : Vec2{0, 0});
        }
      }
      tri.clear();
      if (!triangulatePolygon(corners, tri, limits_.triangulationBudget)) {
        d_.warn(f.line, 0, "this polygon is too tangled to triangulate exactly; the rest of it was fanned");
      }
      for (std::uint32_t t : tri) m.triangles.push_back(ids[t]);
      for (std::uint32_t k = 0; k < f.count; ++k) {
        m.edges.push_back(ids[k]);
        m.edges.push_back(ids[(k + 1) % f.count]);
      }
      m.facetSizes.push_back(f.count);
    }
    runtime::MeshPart part;
    part.name = std::filesystem::path(name_).stem().string();
    if (part.name.empty()) part.name = "object";
    part.triangleIndexCount = static_cast<std::uint32_t>(m.triangles.size());
    part.edgeIndexCount = static_cast<std::uint32_t>(m.edges.size());
    part.facetCount = static_cast<std::uint32_t>(m.facetSizes.size());
    m.parts.push_back(std::move(part));

    LoadedModel model;
    model.format = ModelFormat::kOff;
    ModelObject object;
    object.name = m.parts.front().name;
    object.mesh = std::move(mesh);
    model.objects.push_back(std::move(object));
    model.warnings = d_.finish();
    return model;
  }

  struct Face {
    std::uint32_t first = 0, count = 0, line = 0;
    std::optional<Vec4> colour;
  };

  std::string name_;
  const Limits& limits_;
  Diagnostics d_;
  std::vector<Vec3> positions_;
  std::vector<Vec3> normals_;
  std::vector<Vec4> vertexColours_;
  std::vector<Vec2> texcoords_;
  std::vector<std::uint32_t> faceCorners_;
  std::vector<Face> faces_;
  bool anyFaceColour_ = false;
  std::optional<Diagnostic> firstSkip_;
};

}  // namespace

Result<LoadedModel> parseOffText(std::string_view text, const std::string& name, const LoadOptions& options) {
  OffParser parser(name, options);
  return parser.parse(std::string(text));
}

Result<LoadedModel> readOffFile(std::string bytes, const std::filesystem::path& path, const LoadOptions& options) {
  OffParser parser(path.string(), options);
  auto model = parser.parse(std::move(bytes));
  if (model) model->path = path;
  return model;
}

}  // namespace basalt::formats
