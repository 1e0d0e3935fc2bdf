// An array of trivially copyable values that grows in place, for the largest arrays of the
// library (hierarchical radiosity's links: 8 bytes a link, hundreds of MiB at a million facets).
// Growing a std::vector allocates the new block beside the old one and copies, so its peak is
// the old size plus the new, and the old block, once freed, may stay in the heap. On Linux a
// block of kMapBytes or more is its own mapping, grown or shrunk by mremap (pages move, none is
// copied, a shrunk tail goes back to the system); smaller blocks, and other systems, use
// std::realloc. New values are uninitialized, as for operator new[] of a trivial type.
// Thread safety: a value; const members may be called concurrently.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

#include "core/assert.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace radiosity::detail {

template <typename T>
class GrowableArray {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "realloc moves the bytes: only trivially copyable values");

 public:
  GrowableArray() = default;
  GrowableArray(const GrowableArray&) = delete;
  GrowableArray& operator=(const GrowableArray&) = delete;
  GrowableArray(GrowableArray&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)), mapped_(std::exchange(o.mapped_, 0)) {}
  GrowableArray& operator=(GrowableArray&& o) noexcept {
    if (this != &o) {
      clear();
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      mapped_ = std::exchange(o.mapped_, 0);
    }
    return *this;
  }
  ~GrowableArray() { clear(); }

  /// Makes the array `count` long, keeping the first min(count, size()) values (new ones
  /// uninitialized). Throws std::bad_alloc when it cannot.
  void resize(std::size_t count) {
    if (count == size_) return;
    if (count == 0) {
      clear();
      return;
    }
    const std::size_t bytes = count * sizeof(T);
#if defined(__linux__)
    if (bytes >= kMapBytes) {
      void* grown = nullptr;
      if (mapped_ > 0) {
        grown = mremap(data_, mapped_, bytes, MREMAP_MAYMOVE);
      } else {
        grown = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (grown != MAP_FAILED && size_ > 0) std::memcpy(grown, data_, size_ * sizeof(T));
        if (grown != MAP_FAILED) std::free(data_);
      }
      if (grown == MAP_FAILED) throw std::bad_alloc();
      data_ = static_cast<T*>(grown);
      mapped_ = bytes;
      size_ = count;
      return;
    }
    if (mapped_ > 0) {
      // Small again: back to the heap.
      void* small = std::malloc(bytes);
      if (!small) throw std::bad_alloc();
      std::memcpy(small, data_, bytes);
      munmap(data_, mapped_);
      mapped_ = 0;
      data_ = static_cast<T*>(small);
      size_ = count;
      return;
    }
#endif
    void* grown = std::realloc(data_, bytes);
    if (!grown) throw std::bad_alloc();
    data_ = static_cast<T*>(grown);
    size_ = count;
  }
  /// Frees the block.
  void clear() {
#if defined(__linux__)
    if (mapped_ > 0) munmap(data_, mapped_);
    else
#endif
      std::free(data_);
    data_ = nullptr;
    size_ = 0;
    mapped_ = 0;
  }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T& operator[](std::size_t i) {
    RADIOSITY_ASSERT(i < size_);
    return data_[i];
  }
  const T& operator[](std::size_t i) const {
    RADIOSITY_ASSERT(i < size_);
    return data_[i];
  }

 private:
  /// Blocks this large get their own mapping (Linux).
  static constexpr std::size_t kMapBytes = std::size_t{1} << 20;

  T* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t mapped_ = 0;  ///< bytes of the mapping holding data_ (Linux), or 0 for the heap
};

}  // namespace radiosity::detail
