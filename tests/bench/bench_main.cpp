#include "bench_main.h"

#include <benchmark/benchmark.h>

#include <cstdio>

namespace basalt::bench {
namespace {

/// Prints the usual table and remembers each median in seconds.
class MedianReporter : public benchmark::ConsoleReporter {
 public:
  explicit MedianReporter(Medians& medians) : ConsoleReporter(OO_Tabular), medians_(medians) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.aggregate_name != "median") continue;
      const double perIteration = run.GetAdjustedRealTime();  // in run.time_unit
      medians_[run.run_name.function_name] = perIteration / benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
  }

 private:
  Medians& medians_;
};

}  // namespace

int runBenchmarks(int argc, char** argv, const std::function<void(const Medians&)>& summarise) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  Medians medians;
  MedianReporter reporter(medians);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  std::printf("\n");
  summarise(medians);
  std::fflush(stdout);
  return 0;
}

}  // namespace basalt::bench
