#include "hal/sim/deflate.hpp"

#include <cstdlib>
#include <cstring>

#include "hal/sim/inflate.hpp"

namespace sh::hal {
namespace {

constexpr size_t kMaxStoredBlock = 65535;
constexpr int kHashBits = 15;
constexpr int kWindow = 1 << 15;
constexpr int kMinMatch = 3;
constexpr int kMaxMatch = 258;

constexpr uint16_t kLengthBase[29] = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                      15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                      67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr uint8_t kLengthExtra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                      2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
constexpr uint16_t kDistBase[30] = {1,    2,    3,    4,    5,    7,    9,    13,    17,    25,
                                    33,   49,   65,   97,   129,  193,  257,  385,   513,   769,
                                    1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
constexpr uint8_t kDistExtra[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                    6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

class BitWriter {
 public:
  BitWriter(uint8_t* out, size_t capacity) : out_(out), capacity_(capacity) {}

  void Bits(uint32_t value, int n) {  // least significant bit first
    buffer_ |= value << count_;
    count_ += n;
    while (count_ >= 8) {
      Byte(static_cast<uint8_t>(buffer_));
      buffer_ >>= 8;
      count_ -= 8;
    }
  }
  // Huffman codes are defined most significant bit first.
  void Code(uint32_t code, int n) {
    uint32_t reversed = 0;
    for (int i = 0; i < n; ++i) reversed |= ((code >> i) & 1u) << (n - 1 - i);
    Bits(reversed, n);
  }
  void AlignToByte() {
    if (count_ > 0) Bits(0, 8 - count_);
  }
  void Byte(uint8_t b) {
    if (size_ < capacity_) {
      out_[size_] = b;
    } else {
      overflow_ = true;
    }
    ++size_;
  }
  size_t size() const { return size_; }
  bool overflow() const { return overflow_; }

 private:
  uint8_t* out_;
  size_t capacity_;
  size_t size_ = 0;
  uint32_t buffer_ = 0;
  int count_ = 0;
  bool overflow_ = false;
};

void FixedSymbol(BitWriter& w, int symbol) {
  if (symbol < 144) {
    w.Code(0x30 + symbol, 8);
  } else if (symbol < 256) {
    w.Code(0x190 + (symbol - 144), 9);
  } else if (symbol < 280) {
    w.Code(symbol - 256, 7);
  } else {
    w.Code(0xc0 + (symbol - 280), 8);
  }
}

void FixedMatch(BitWriter& w, int length, int distance) {
  int li = 28;
  while (kLengthBase[li] > length) --li;
  FixedSymbol(w, 257 + li);
  w.Bits(length - kLengthBase[li], kLengthExtra[li]);
  int di = 29;
  while (kDistBase[di] > distance) --di;
  w.Code(di, 5);
  w.Bits(distance - kDistBase[di], kDistExtra[di]);
}

uint32_t Hash3(const uint8_t* p) {
  const uint32_t v = p[0] | (p[1] << 8) | (p[2] << 16);
  return (v * 2654435761u) >> (32 - kHashBits);
}

// One fixed-Huffman block over the whole input, greedy matching against the most recent
// position with the same 3-byte hash.
void CompressFixed(const uint8_t* in, size_t size, int32_t* head, BitWriter& w) {
  for (int i = 0; i < (1 << kHashBits); ++i) head[i] = -1;
  w.Bits(1, 1);  // final block
  w.Bits(1, 2);  // fixed Huffman
  size_t i = 0;
  while (i < size && !w.overflow()) {
    int best = 0;
    size_t best_distance = 0;
    if (i + kMinMatch <= size) {
      const uint32_t h = Hash3(in + i);
      const int32_t candidate = head[h];
      head[h] = static_cast<int32_t>(i);
      if (candidate >= 0 && i - static_cast<size_t>(candidate) <= kWindow) {
        const size_t limit = size - i < kMaxMatch ? size - i : kMaxMatch;
        size_t n = 0;
        while (n < limit && in[candidate + n] == in[i + n]) ++n;
        if (n >= kMinMatch) {
          best = static_cast<int>(n);
          best_distance = i - static_cast<size_t>(candidate);
        }
      }
    }
    if (best > 0) {
      FixedMatch(w, best, static_cast<int>(best_distance));
      // Index the skipped positions too so later matches can find them.
      for (size_t k = i + 1; k < i + best && k + kMinMatch <= size; ++k) {
        head[Hash3(in + k)] = static_cast<int32_t>(k);
      }
      i += best;
    } else {
      FixedSymbol(w, in[i]);
      ++i;
    }
  }
  FixedSymbol(w, 256);
}

void CompressStored(const uint8_t* in, size_t size, BitWriter& w) {
  size_t done = 0;
  do {
    const size_t n = size - done < kMaxStoredBlock ? size - done : kMaxStoredBlock;
    w.Bits(done + n == size ? 1 : 0, 1);
    w.Bits(0, 2);
    w.AlignToByte();
    w.Bits(static_cast<uint32_t>(n), 16);
    w.Bits(static_cast<uint32_t>(~n & 0xffff), 16);
    for (size_t k = 0; k < n; ++k) w.Byte(in[done + k]);
    done += n;
  } while (done < size);
}

void Header(BitWriter& w) {
  w.Byte(0x78);  // deflate, 32 KiB window
  w.Byte(0x01);  // fastest-compression level hint; 0x7801 % 31 == 0
}

void Trailer(const uint8_t* in, size_t size, BitWriter& w) {
  w.AlignToByte();
  const uint32_t adler = Adler32(in, size);
  for (int shift = 24; shift >= 0; shift -= 8) w.Byte(static_cast<uint8_t>(adler >> shift));
}

}  // namespace

size_t ZlibDeflateBound(size_t size) {
  const size_t blocks = size == 0 ? 1 : (size + kMaxStoredBlock - 1) / kMaxStoredBlock;
  return 2 + size + 5 * blocks + 4;
}

Result<size_t> ZlibDeflate(const uint8_t* in, size_t size, uint8_t* out, size_t capacity) {
  const size_t stored_size = ZlibDeflateBound(size);
  auto* head = static_cast<int32_t*>(std::malloc(sizeof(int32_t) << kHashBits));
  if (head == nullptr) {
    return Status::Error(StatusCode::kResourceExhausted, "deflate: out of memory for hash table");
  }
  // Try fixed Huffman within the stored size; if it does not beat stored blocks, store.
  const size_t fixed_capacity = capacity < stored_size ? capacity : stored_size;
  BitWriter fixed(out, fixed_capacity);
  Header(fixed);
  CompressFixed(in, size, head, fixed);
  Trailer(in, size, fixed);
  std::free(head);
  if (!fixed.overflow() && fixed.size() < stored_size) return fixed.size();

  BitWriter stored(out, capacity);
  Header(stored);
  CompressStored(in, size, stored);
  Trailer(in, size, stored);
  if (stored.overflow()) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "deflate: output buffer of %zu bytes too small (%zu needed)", capacity,
                         stored.size());
  }
  return stored.size();
}

}  // namespace sh::hal
