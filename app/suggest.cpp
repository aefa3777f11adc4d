#include "app/suggest.h"

#include <vector>

#include <fmt/format.h>

#include "runtime/script/command_table.h"
#include "runtime/script/lexer.h"

namespace basalt::kiosk {

std::optional<std::string_view> nearestWord(std::string_view word, std::span<const std::string_view> candidates) {
  if (word.empty() || word.size() > kMaxSuggestedWord) return std::nullopt;
  std::vector<std::string_view> compared;
  compared.reserve(std::min(candidates.size(), kMaxSuggestionCandidates));
  for (const std::string_view c : candidates.first(std::min(candidates.size(), kMaxSuggestionCandidates))) {
    if (c.size() > kMaxSuggestedWord || c == word) continue;
    if (script::equalsIgnoreCase(c, word)) return c;  // "--Frames" for "--frames"
    compared.push_back(c);
  }
  // The script language's measure (optimal string alignment, without case, a tolerance that
  // grows with the word's length), so that the CLI and the script checker agree.
  return script::closestMatch(word, compared);
}

std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates,
                       std::string_view otherwise) {
  const auto guess = nearestWord(word, candidates);
  return guess ? fmt::format("; did you mean '{}'?", *guess) : std::string(otherwise);
}

}  // namespace basalt::kiosk
