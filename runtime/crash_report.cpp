#include "runtime/crash_report.h"

#include <execinfo.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace basalt::runtime {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

constexpr std::array<int, 5> kSignals = {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT};
constexpr std::size_t kAltStackBytes = std::size_t{64} * 1024;
constexpr int kMaxFrames = 64;

const char* gProgram = "basalt";  // set once at install, read in the handler
alignas(16) std::array<unsigned char, kAltStackBytes> gAltStack;

void put(const char* s) {
  std::size_t n = std::strlen(s);
  while (n > 0) {
    const ssize_t w = ::write(STDERR_FILENO, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<std::size_t>(w);
  }
}

/// Hexadecimal without printf (not async-signal-safe).
void putHex(std::uintptr_t v) {
  char buf[2 + 2 * sizeof v + 1];
  buf[0] = '0';
  buf[1] = 'x';
  for (std::size_t i = 0; i < 2 * sizeof v; ++i) {
    const unsigned digit = static_cast<unsigned>((v >> (4 * (2 * sizeof v - 1 - i))) & 0xfU);
    buf[2 + i] = static_cast<char>(digit < 10 ? '0' + digit : 'a' + digit - 10);
  }
  buf[sizeof buf - 1] = '\0';
  put(buf);
}

const char* signalName(int sig) {
  switch (sig) {
    case SIGSEGV: return "SIGSEGV (invalid memory access)";
    case SIGBUS: return "SIGBUS (bus error)";
    case SIGILL: return "SIGILL (illegal instruction)";
    case SIGFPE: return "SIGFPE (arithmetic error)";
    case SIGABRT: return "SIGABRT (aborted)";
    default: return "a fatal signal";
  }
}

void onCrash(int sig, siginfo_t* info, void* /*context*/) {
  // Once: a second fault inside the report goes straight to the default action.
  struct sigaction dfl{};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  for (const int s : kSignals) ::sigaction(s, &dfl, nullptr);
  put(gProgram);
  put(": crashed: ");
  put(signalName(sig));
  if (sig != SIGABRT && info) {
    put(" at address ");
    putHex(reinterpret_cast<std::uintptr_t>(info->si_addr));
  }
  put("; call stack (newest first):\n");
  std::array<void*, kMaxFrames> frames{};
  const int n = ::backtrace(frames.data(), kMaxFrames);
  ::backtrace_symbols_fd(frames.data(), n, STDERR_FILENO);
  put(gProgram);
  put(": end of the call stack; resolve addresses with addr2line -f -C -e BINARY OFFSET\n");
  ::raise(sig);
}

}  // namespace

void installCrashReport(const char* program) {
  if (kSanitized) return;
  gProgram = program;
  // backtrace() loads libgcc on its first call, which may allocate: do it now, not in a crash.
  std::array<void*, 2> warm{};
  (void)::backtrace(warm.data(), static_cast<int>(warm.size()));
  stack_t stack{};
  stack.ss_sp = gAltStack.data();
  stack.ss_size = gAltStack.size();
  stack.ss_flags = 0;
  ::sigaltstack(&stack, nullptr);
  struct sigaction action{};
  action.sa_sigaction = onCrash;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  for (const int s : kSignals) ::sigaction(s, &action, nullptr);
}

}  // namespace basalt::runtime
