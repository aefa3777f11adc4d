#pragma once

/// \file
/// \brief Shared main() for Basalt's benchmarks: runs the registered Google Benchmarks, keeps
/// the median of each, and lets the benchmark file print its comparison lines (figure, the
/// baseline measured in the same run, the ratio and the target).

#include <functional>
#include <map>
#include <string>

namespace basalt::bench {

/// \brief Median time per iteration in seconds, by benchmark function name.
using Medians = std::map<std::string, double>;

/// \brief Runs the benchmarks, then calls `summarise` with the medians.
int runBenchmarks(int argc, char** argv, const std::function<void(const Medians&)>& summarise);

}  // namespace basalt::bench
