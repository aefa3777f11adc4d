#pragma once

/// \file
/// \brief "Did you mean": the nearest of a few known words to a misspelt one, for commands,
/// options and part names typed on the command line.

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace basalt::kiosk {

/// \brief Longest word compared; a longer one gets no suggestion (nobody misspells a paragraph).
inline constexpr std::size_t kMaxSuggestedWord = 64;
/// \brief Candidates compared at most; those past it are not considered.
inline constexpr std::size_t kMaxSuggestionCandidates = 256;

/// \brief The candidate `word` most likely meant, or nothing when none is close. A candidate
/// that differs only in case is suggested first. Bounded: words longer than kMaxSuggestedWord and
/// candidates past the first kMaxSuggestionCandidates (or longer than kMaxSuggestedWord) are not
/// compared, so a long argument or a show with thousands of parts costs little.
[[nodiscard]] std::optional<std::string_view> nearestWord(std::string_view word,
                                                          std::span<const std::string_view> candidates);

/// \brief "; did you mean 'run'?" when `nearestWord` finds one, else `otherwise` (such as
/// "; see 'basalt --help'"): the end of an "unknown ..." message.
[[nodiscard]] std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates,
                                     std::string_view otherwise = {});

}  // namespace basalt::kiosk
