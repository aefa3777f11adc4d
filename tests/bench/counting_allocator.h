#pragma once

/// \file
/// \brief A counting global operator new for benchmarks that check "allocates nothing per frame".
/// Linking counting_allocator.cpp into a binary replaces operator new/delete there; the count
/// covers every C++ allocation in the process (not C code's malloc, such as the GL driver's).

#include <cstdint>

namespace basalt::bench {

/// \brief Allocations made through operator new since the process started.
std::uint64_t allocationCount();

}  // namespace basalt::bench
