#pragma once
/// \file
/// Delegator<Args...>: the light delegate (event) system (after EnTT's `delegate` and `sigh`).
///
/// A delegate is a function pointer plus a payload pointer. A Delegator keeps an ordered list of
/// delegates and calls all of them on broadcast(). Binding kinds:
///   - a free function:                 `d.add_delegate<&on_contact>()`
///   - a member function on an object:  `d.add_delegate<&Robot::on_contact>(robot)`
///   - a free function with a payload:  `d.add_delegate<&on_contact_with>(state)`  (called as
///                                      `on_contact_with(state, args...)`)
///   - any callable (lambda with captures): `d.add_delegate([&](const Contact& c) { ... })`;
///     the delegator stores a heap copy of it (allocation happens here, at bind time only).
///
/// Arguments are passed by reference, never copied by the delegator: for a value parameter type
/// `T` in Args the delegates receive `const T&`; for a reference type `T&` they receive `T&`
/// (delegates of a `Delegator<Force&>` may therefore modify the argument in turn, in bind order).
///
/// Binding and removal during a broadcast (defined behaviour):
///   - a delegate bound during a broadcast is not called by that broadcast, only by later ones;
///   - a delegate removed during a broadcast (itself or another one) is not called afterwards,
///     including later in the same broadcast if it was not reached yet;
///   - removed slots are only marked during a broadcast; they are compacted (and an owned callable
///     destroyed) by the next add/remove/clear made outside any broadcast, or by the destructor.
///     A lambda may therefore remove itself safely: its captures stay alive until then;
///   - broadcast() itself never allocates or frees memory, even when delegates bind or remove
///     during it (binding during a broadcast may allocate, as binding always may);
///   - nested broadcasts (a delegate broadcasting the same delegator) are allowed.
///
/// Thread rules: a Delegator is NOT a cross-thread primitive. Binding, removing and broadcasting
/// happen on one thread, or all binding happens before the broadcasting thread starts (with the
/// thread start as the synchronisation point) and nothing binds while it runs. An owner enforces
/// the latter with refuse_binding() while its thread runs: binding then fails visibly (an invalid
/// handle, an empty connection, a logged error, a count) instead of racing. To move events across
/// threads use SpscQueue or LatestValue.
///
/// Real-time: broadcast() is real-time safe if the bound delegates are (no allocation, no locks,
/// no exceptions thrown by the delegator itself). add_delegate/remove_delegate/clear are not.
///
/// Lifetime: a Delegator is neither copyable nor movable, because sinks and ScopedConnections
/// point at it; it must outlive them. Objects bound by reference must outlive their binding.

#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "uh/core/log.hpp"

namespace uh {

/// Identifies one binding in a Delegator. Ids are unique across all delegators of the process;
/// a default-constructed handle identifies nothing.
struct DelegateHandle {
  std::uint64_t id = 0;  ///< 0 = no binding

  [[nodiscard]] bool valid() const { return id != 0; }
  friend bool operator==(const DelegateHandle&, const DelegateHandle&) = default;
};

namespace detail {

/// How a Delegator<Args...> passes one argument: by reference, never by value.
template <typename T>
using DelegateArg = std::conditional_t<std::is_lvalue_reference_v<T>, T, const std::remove_cvref_t<T>&>;

inline std::uint64_t next_delegate_id() {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}

}  // namespace detail

template <typename... Args>
class Delegator;

/// RAII connection: removes its binding from the delegator when destroyed (or on disconnect()).
/// Movable, not copyable. The delegator must outlive the connection; destroy or release() the
/// connection on the delegator's thread (see Delegator's thread rules).
class [[nodiscard]] ScopedConnection {
 public:
  ScopedConnection() = default;

  /// Takes ownership of `handle`, a binding of `delegator`.
  /// Takes ownership of `handle`, a binding of `delegator`; an invalid handle (a refused binding)
  /// gives an empty connection.
  template <typename... Args>
  ScopedConnection(Delegator<Args...>& delegator, DelegateHandle handle)
      : owner_(handle.valid() ? &delegator : nullptr), handle_(handle), remove_(&remove_from<Args...>) {}

  ScopedConnection(const ScopedConnection&) = delete;
  ScopedConnection& operator=(const ScopedConnection&) = delete;
  ScopedConnection(ScopedConnection&& other) noexcept
      : owner_(std::exchange(other.owner_, nullptr)),
        handle_(std::exchange(other.handle_, DelegateHandle{})),
        remove_(std::exchange(other.remove_, nullptr)) {}
  ScopedConnection& operator=(ScopedConnection&& other) noexcept {
    if (this != &other) {
      disconnect();
      owner_ = std::exchange(other.owner_, nullptr);
      handle_ = std::exchange(other.handle_, DelegateHandle{});
      remove_ = std::exchange(other.remove_, nullptr);
    }
    return *this;
  }
  ~ScopedConnection() { disconnect(); }

  /// Removes the binding now (no effect if already disconnected or released).
  void disconnect() {
    if (owner_ != nullptr) {
      remove_(owner_, handle_);
      owner_ = nullptr;
      handle_ = {};
    }
  }

  /// Gives up ownership without removing the binding; returns its handle.
  DelegateHandle release() {
    owner_ = nullptr;
    return std::exchange(handle_, DelegateHandle{});
  }

  /// True while this object owns a binding (it may have been removed through its handle since).
  [[nodiscard]] bool connected() const { return owner_ != nullptr; }
  [[nodiscard]] DelegateHandle handle() const { return handle_; }

 private:
  template <typename... Args>
  static void remove_from(void* owner, DelegateHandle handle) {
    static_cast<Delegator<Args...>*>(owner)->remove_delegate(handle);
  }

  void* owner_ = nullptr;
  DelegateHandle handle_{};
  void (*remove_)(void*, DelegateHandle) = nullptr;
};

/// An ordered list of delegates called by broadcast(). See the file comment for binding kinds,
/// behaviour during broadcast, thread rules and lifetime.
template <typename... Args>
class Delegator {
  static_assert((!std::is_rvalue_reference_v<Args> && ...),
                "uh::Delegator: rvalue reference arguments cannot be passed to several delegates");

 public:
  /// The signature every delegate is called with.
  using Thunk = void (*)(void* payload, detail::DelegateArg<Args>... args);

  Delegator() = default;
  Delegator(const Delegator&) = delete;
  Delegator& operator=(const Delegator&) = delete;
  Delegator(Delegator&&) = delete;
  Delegator& operator=(Delegator&&) = delete;
  ~Delegator() {
    assert(depth_ == 0 && "uh::Delegator::~Delegator(): destroyed during its own broadcast");
    for (Entry& e : entries_) destroy(e);
  }

  /// Binds a free function `void f(Args...)` (parameters may be references). Not real-time safe.
  template <auto Function>
    requires std::is_invocable_v<decltype(Function), detail::DelegateArg<Args>...>
  DelegateHandle add_delegate() {
    return insert(&call_free<Function>, nullptr, nullptr);
  }

  /// Binds a member function `&Class::method` on `instance`, or a free function
  /// `f(Class&, Args...)` with `instance` as its first argument. `instance` is held by reference
  /// and must outlive the binding. Not real-time safe.
  template <auto Candidate, typename Class>
    requires std::is_invocable_v<decltype(Candidate), Class&, detail::DelegateArg<Args>...>
  DelegateHandle add_delegate(Class& instance) {
    void* payload = const_cast<void*>(static_cast<const void*>(std::addressof(instance)));
    return insert(&call_bound<Candidate, Class>, payload, nullptr);
  }

  /// Binds a copy (or moved instance) of any callable, e.g. a lambda with captures. The delegator
  /// owns the copy on the heap (allocates here, never in broadcast()). Not real-time safe.
  template <typename Callable>
    requires(!std::is_same_v<std::remove_cvref_t<Callable>, DelegateHandle> &&
             std::is_invocable_v<std::remove_cvref_t<Callable>&, detail::DelegateArg<Args>...>)
  DelegateHandle add_delegate(Callable&& callable) {
    using Stored = std::remove_cvref_t<Callable>;
    auto owned = std::make_unique<Stored>(std::forward<Callable>(callable));
    const DelegateHandle handle = insert(&call_owned<Stored>, owned.get(), &delete_owned<Stored>);
    owned.release();  // now owned by the entry (or already deleted by insert() if refused)
    return handle;
  }

  /// Like add_delegate, but returns an RAII connection that removes the binding when destroyed.
  template <auto Function>
  ScopedConnection connect() {
    return ScopedConnection(*this, add_delegate<Function>());
  }
  template <auto Candidate, typename Class>
  ScopedConnection connect(Class& instance) {
    return ScopedConnection(*this, add_delegate<Candidate>(instance));
  }
  template <typename Callable>
  ScopedConnection connect(Callable&& callable) {
    return ScopedConnection(*this, add_delegate(std::forward<Callable>(callable)));
  }

  /// Removes a binding. Returns false if `handle` is unknown to this delegator or already removed.
  /// During a broadcast the delegate is not called any more but its slot is kept until the next
  /// mutation outside a broadcast (see the file comment). Not real-time safe.
  bool remove_delegate(DelegateHandle handle) {
    if (!handle.valid()) return false;
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      Entry& e = entries_[i];
      if (e.id != handle.id || e.fn == nullptr) continue;
      e.fn = nullptr;
      --live_;
      compact_if_idle();
      return true;
    }
    return false;
  }

  /// Removes every binding (during a broadcast: none of them is called any more). Not real-time safe.
  void clear() {
    for (Entry& e : entries_) e.fn = nullptr;
    live_ = 0;
    compact_if_idle();
  }

  /// Calls every bound delegate in bind order with references to `args`. Never allocates;
  /// real-time safe if the delegates are. Exceptions thrown by a delegate propagate (the
  /// delegator stays consistent) and skip the remaining delegates.
  void broadcast(detail::DelegateArg<Args>... args) {
    // iterate by index over the count at entry: bindings added meanwhile (which may reallocate
    // entries_) are not called now, and removed ones have fn == nullptr
    const std::size_t count = entries_.size();
    DepthGuard guard{depth_};
    for (std::size_t i = 0; i < count; ++i) {
      // copy the slot: a delegate that binds may reallocate entries_ during the call
      const Thunk fn = entries_[i].fn;
      if (fn != nullptr) fn(entries_[i].payload, args...);
    }
  }

  /// Number of live bindings (removed ones excluded, even while their slot is still kept).
  [[nodiscard]] std::size_t size() const { return live_; }
  [[nodiscard]] bool empty() const { return live_ == 0; }

  /// Reserves room for `n` bindings so that later binds do not reallocate. Not real-time safe.
  void reserve(std::size_t n) { entries_.reserve(n); }

  /// Refuses every binding until allow_binding(): add_delegate() returns an invalid handle and
  /// connect() an empty connection, `reason` is logged as an error and refused_bindings() counts
  /// the attempt. For an owner whose broadcasting thread runs. `reason` must outlive the refusal
  /// (a string literal). Owner's thread; not real-time safe.
  void refuse_binding(const char* reason) { refusal_ = reason; }
  /// Ends refuse_binding(). Owner's thread.
  void allow_binding() { refusal_ = nullptr; }
  [[nodiscard]] bool binding_refused() const { return refusal_ != nullptr; }
  /// Bindings refused so far.
  [[nodiscard]] std::uint64_t refused_bindings() const { return refused_; }

 private:
  struct Entry {
    Thunk fn = nullptr;  ///< nullptr once removed
    void* payload = nullptr;
    void (*deleter)(void*) = nullptr;  ///< set when the entry owns payload
    std::uint64_t id = 0;
  };

  struct DepthGuard {
    int& depth;
    explicit DepthGuard(int& d) : depth(d) { ++depth; }
    ~DepthGuard() { --depth; }
    DepthGuard(const DepthGuard&) = delete;
    DepthGuard& operator=(const DepthGuard&) = delete;
  };

  template <auto Function>
  static void call_free(void*, detail::DelegateArg<Args>... args) {
    std::invoke(Function, args...);
  }

  template <auto Candidate, typename Class>
  static void call_bound(void* payload, detail::DelegateArg<Args>... args) {
    std::invoke(Candidate, *static_cast<Class*>(payload), args...);
  }

  template <typename Stored>
  static void call_owned(void* payload, detail::DelegateArg<Args>... args) {
    std::invoke(*static_cast<Stored*>(payload), args...);
  }

  template <typename Stored>
  static void delete_owned(void* payload) {
    delete static_cast<Stored*>(payload);
  }

  static void destroy(Entry& e) {
    if (e.deleter != nullptr) e.deleter(e.payload);
    e.deleter = nullptr;
    e.payload = nullptr;
  }

  DelegateHandle insert(Thunk fn, void* payload, void (*deleter)(void*)) {
    if (refusal_ != nullptr) {
      if (deleter != nullptr) deleter(payload);
      ++refused_;
      log::error("{}", refusal_);
      return DelegateHandle{};
    }
    compact_if_idle();
    const DelegateHandle handle{detail::next_delegate_id()};
    try {
      entries_.push_back(Entry{fn, payload, deleter, handle.id});
    } catch (...) {
      if (deleter != nullptr) deleter(payload);
      throw;
    }
    ++live_;
    return handle;
  }

  // drop removed slots (and destroy what they own), but never while a broadcast is running
  void compact_if_idle() {
    if (depth_ != 0 || live_ == entries_.size()) return;
    std::size_t out = 0;
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      if (entries_[i].fn == nullptr) {
        destroy(entries_[i]);
      } else {
        entries_[out++] = entries_[i];
      }
    }
    entries_.resize(out);
  }

  std::vector<Entry> entries_;
  std::size_t live_ = 0;
  int depth_ = 0;
  const char* refusal_ = nullptr;  // set while binding is refused
  std::uint64_t refused_ = 0;
};

/// The binding side of a Delegator, for classes that keep their Delegator private (EnTT's sink):
///   `DelegateSink<const Contact&> on_contact() { return DelegateSink{contact_event_}; }`
/// Exposes binding and removal only, never broadcast(). Same thread rules as the Delegator; it
/// holds a pointer to it, so the Delegator must outlive the sink.
template <typename... Args>
class DelegateSink {
 public:
  explicit DelegateSink(Delegator<Args...>& delegator) : delegator_(&delegator) {}

  template <auto Function>
  DelegateHandle add_delegate() {
    return delegator_->template add_delegate<Function>();
  }
  template <auto Candidate, typename Class>
  DelegateHandle add_delegate(Class& instance) {
    return delegator_->template add_delegate<Candidate>(instance);
  }
  template <typename Callable>
  DelegateHandle add_delegate(Callable&& callable) {
    return delegator_->add_delegate(std::forward<Callable>(callable));
  }

  template <auto Function>
  ScopedConnection connect() {
    return delegator_->template connect<Function>();
  }
  template <auto Candidate, typename Class>
  ScopedConnection connect(Class& instance) {
    return delegator_->template connect<Candidate>(instance);
  }
  template <typename Callable>
  ScopedConnection connect(Callable&& callable) {
    return delegator_->connect(std::forward<Callable>(callable));
  }

  bool remove_delegate(DelegateHandle handle) { return delegator_->remove_delegate(handle); }
  [[nodiscard]] bool binding_refused() const { return delegator_->binding_refused(); }
  [[nodiscard]] std::size_t size() const { return delegator_->size(); }
  [[nodiscard]] bool empty() const { return delegator_->empty(); }

 private:
  Delegator<Args...>* delegator_;
};

template <typename... Args>
DelegateSink(Delegator<Args...>&) -> DelegateSink<Args...>;

}  // namespace uh
