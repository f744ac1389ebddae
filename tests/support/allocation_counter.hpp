#pragma once
// Counts heap allocations made by the calling thread while a scope is active, so tests can prove
// that real-time paths never allocate. The replaced global operator new lives in
// allocation_counter.cpp.

#include <cstdint>

namespace uh::test {

/// Allocations made on this thread since the counter was created.
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  std::uint64_t count() const;

 private:
  std::uint64_t start_;
};

}  // namespace uh::test
