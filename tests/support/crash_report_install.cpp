// Linked into every test binary: a test process that crashes prints the signal and its call
// stack (runtime/crash_report.h) before it dies, so that a crash in CI leaves more than
// "SEGFAULT" in the log.

#include "runtime/crash_report.h"

namespace {
[[maybe_unused]] const bool kInstalled = (basalt::runtime::installCrashReport("test"), true);
}  // namespace
