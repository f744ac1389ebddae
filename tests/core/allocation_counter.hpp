#pragma once
// Counts global operator new calls while armed (the replacement lives in allocation_counter.cpp
// and applies to the whole test program; only armed sections count).

#include <cstdint>

namespace uh::test {

void arm_allocation_counter();
/// Disarms and returns the number of allocations since arming.
std::uint64_t disarm_allocation_counter();

}  // namespace uh::test
