// Bounded vector with inline storage and a size-erased base.
//
// `Vector<T, N>` owns storage for N elements; it converts to `Vector<T>&`, which functions take
// so that they work with any capacity (the Pigweed/ETL pattern). Nothing here touches the heap.
// When full, push_back() returns false and leaves the vector unchanged: callers decide whether
// that is an error (most report kResourceExhausted) or a defined truncation.
#pragma once

#include <cassert>
#include <cstddef>
#include <limits>
#include <type_traits>

namespace sh {

inline constexpr size_t kGenericCapacity = std::numeric_limits<size_t>::max();

template <typename T, size_t N = kGenericCapacity>
class Vector;

// Size-erased base: refers to storage owned by the derived Vector<T, N>.
template <typename T>
class Vector<T, kGenericCapacity> {
  static_assert(std::is_trivially_destructible_v<T>,
                "Vector holds trivially destructible elements only");

 public:
  using value_type = T;
  using iterator = T*;
  using const_iterator = const T*;

  Vector(const Vector&) = delete;
  Vector& operator=(const Vector& other) {
    if (this == &other) return *this;
    assert(other.size_ <= capacity_);
    size_ = other.size_ <= capacity_ ? other.size_ : capacity_;
    for (size_t i = 0; i < size_; ++i) data_[i] = other.data_[i];
    return *this;
  }

  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == capacity_; }

  T* data() { return data_; }
  const T* data() const { return data_; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

  T& operator[](size_t i) {
    assert(i < size_);
    return data_[i];
  }
  const T& operator[](size_t i) const {
    assert(i < size_);
    return data_[i];
  }
  T& back() {
    assert(size_ > 0);
    return data_[size_ - 1];
  }

  // Returns false (and stores nothing) when the vector is full.
  [[nodiscard]] bool push_back(const T& value) {
    if (size_ == capacity_) return false;
    data_[size_++] = value;
    return true;
  }
  void pop_back() {
    assert(size_ > 0);
    --size_;
  }
  void clear() { size_ = 0; }
  // Shrinks, or grows with default-initialised elements up to capacity. Returns false if n
  // exceeds the capacity (then the size becomes the capacity).
  bool resize(size_t n) {
    const bool fits = n <= capacity_;
    const size_t target = fits ? n : capacity_;
    for (size_t i = size_; i < target; ++i) data_[i] = T{};
    size_ = target;
    return fits;
  }
  // Removes element i by moving the last element into its place (order not kept).
  void swap_remove(size_t i) {
    assert(i < size_);
    data_[i] = data_[size_ - 1];
    --size_;
  }

 protected:
  Vector(T* data, size_t capacity) : data_(data), capacity_(capacity) {}
  ~Vector() = default;

 private:
  T* data_;
  size_t capacity_;
  size_t size_ = 0;
};

template <typename T, size_t N>
class Vector : public Vector<T, kGenericCapacity> {
 public:
  static constexpr size_t kCapacity = N;
  Vector() : Vector<T, kGenericCapacity>(storage_, N) {}
  Vector(const Vector& other) : Vector() { *this = other; }
  Vector& operator=(const Vector& other) {
    if (this == &other) return *this;
    Vector<T, kGenericCapacity>::operator=(other);
    return *this;
  }

 private:
  T storage_[N] = {};
};

}  // namespace sh
