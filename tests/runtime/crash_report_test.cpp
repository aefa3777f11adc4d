// A crash leaves its cause behind (runtime/crash_report.h): the process names the signal, the
// faulting address and its call stack on standard error, and still dies of that signal (so a
// service manager and core dumps see the real cause).
// Example failures: a handler that swallows the signal (the process exits 0 or hangs); a report
// with no call stack; a report that itself crashes before saying anything.

#include <gtest/gtest.h>

#include <signal.h>

#include <cstdint>
#include <cstdlib>

#include "runtime/crash_report.h"

namespace basalt::runtime {
namespace {

#if defined(__SANITIZE_ADDRESS__)
#define BASALT_SKIP_UNDER_ASAN() GTEST_SKIP() << "AddressSanitizer reports crashes itself (the handler stays out)"
#else
#define BASALT_SKIP_UNDER_ASAN() (void)0
#endif

// The address to write to, read at run time (the compiler cannot see the fault coming).
volatile std::uintptr_t gUnmapped = 0x10;

[[gnu::noinline]] void writeToUnmappedMemory() { *reinterpret_cast<volatile int*>(gUnmapped) = 42; }

TEST(CrashReport, AnInvalidAccessNamesTheSignalTheAddressAndTheStack) {
  BASALT_SKIP_UNDER_ASAN();
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        installCrashReport("crash-test");
        writeToUnmappedMemory();
      },
      testing::KilledBySignal(SIGSEGV),
      "crash-test: crashed: SIGSEGV \\(invalid memory access\\) at address 0x0+10; call stack \\(newest "
      "first\\):\n(.*\n)+crash-test: end of the call stack");
}

TEST(CrashReport, AnAbortIsReportedAndStillAnAbort) {
  BASALT_SKIP_UNDER_ASAN();
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        installCrashReport("crash-test");
        std::abort();
      },
      testing::KilledBySignal(SIGABRT), "crash-test: crashed: SIGABRT \\(aborted\\); call stack");
}

}  // namespace
}  // namespace basalt::runtime
