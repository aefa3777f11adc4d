#pragma once

/// \file
/// \brief What a crash leaves behind: on SIGSEGV, SIGBUS, SIGILL, SIGFPE or SIGABRT the process
/// writes one line naming the signal and the faulting address, and the call stack (function
/// names where the binary has them), to standard error, then dies of the same signal as it
/// would have (so systemd, a test runner or a shell see the real cause and core dumps still
/// happen). Under systemd standard error is the journal: the operator finds the stack there,
/// after the service was restarted.
///
/// Threading: install once, early, from the main thread. The handler uses only async-signal-safe
/// calls (write, backtrace_symbols_fd) on an alternate stack, so a stack overflow reports too.

namespace basalt::runtime {

/// \brief Installs the crash report handlers. A no-op when built with AddressSanitizer, whose
/// own report is better. `program` names the process in the report's first line (kept, not
/// copied: a string literal).
void installCrashReport(const char* program);

}  // namespace basalt::runtime
