#include "hal/sim/inflate.hpp"

namespace sh::hal {
namespace {

constexpr int kMaxBits = 15;        // longest DEFLATE code
constexpr int kMaxLitLen = 288;     // literal/length alphabet (286 used + 2 reserved)
constexpr int kMaxDist = 30;        // distance alphabet
constexpr int kWindow = 1 << 15;    // largest back-reference distance
constexpr int kRing = 2 * kWindow;  // ring buffer: the last kWindow bytes are always present

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
// Order in which code-length code lengths are stored in a dynamic block header.
constexpr uint8_t kCodeLengthOrder[19] = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                          11, 4,  12, 3, 13, 2, 14, 1, 15};

// Canonical Huffman code as counts per length and symbols sorted by code; decoded one bit at a
// time, which is simple to get right and fast enough for simulator images.
struct Huffman {
  uint16_t count[kMaxBits + 1];
  uint16_t symbol[kMaxLitLen];
};

// Builds the decoding tables. Returns 0 for a complete code, > 0 for an incomplete one, < 0 for
// an over-subscribed one (impossible to decode).
int BuildHuffman(Huffman& h, const uint8_t* lengths, int n) {
  for (int len = 0; len <= kMaxBits; ++len) h.count[len] = 0;
  for (int s = 0; s < n; ++s) h.count[lengths[s]]++;
  if (h.count[0] == n) return 0;  // no codes: complete but unusable; decoding it fails cleanly
  int left = 1;
  for (int len = 1; len <= kMaxBits; ++len) {
    left <<= 1;
    left -= h.count[len];
    if (left < 0) return left;
  }
  uint16_t offsets[kMaxBits + 1];
  offsets[1] = 0;
  for (int len = 1; len < kMaxBits; ++len) offsets[len + 1] = offsets[len] + h.count[len];
  for (int s = 0; s < n; ++s) {
    if (lengths[s] != 0) h.symbol[offsets[lengths[s]]++] = static_cast<uint16_t>(s);
  }
  return left;
}

class Inflater {
 public:
  Inflater(ByteSource& source, ByteSink& sink) : source_(source), sink_(sink) {}

  Status Run() {
    const int cmf = Bits(8), flg = Bits(8);
    if (truncated_) return Truncated();
    if ((cmf & 0x0f) != 8 || (cmf >> 4) > 7) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "zlib: unsupported compression method %d / window %d", cmf & 0x0f,
                           cmf >> 4);
    }
    if ((cmf * 256 + flg) % 31 != 0) {
      return Status::Error(StatusCode::kInvalidArgument, "zlib: header check bits are wrong");
    }
    if (flg & 0x20) {
      return Status::Error(StatusCode::kInvalidArgument, "zlib: preset dictionary not supported");
    }
    bool last = false;
    while (!last) {
      last = Bits(1) != 0;
      const int type = Bits(2);
      if (truncated_) return Truncated();
      switch (type) {
        case 0:
          SH_RETURN_IF_ERROR(Stored());
          break;
        case 1:
          SH_RETURN_IF_ERROR(Fixed());
          break;
        case 2:
          SH_RETURN_IF_ERROR(Dynamic());
          break;
        default:
          return Status::Error(StatusCode::kInvalidArgument, "deflate: invalid block type 3");
      }
    }
    SH_RETURN_IF_ERROR(Flush());
    // Trailer: Adler-32 of the uncompressed data, big-endian, byte aligned.
    bit_count_ = 0;
    uint32_t stored = 0;
    for (int i = 0; i < 4; ++i) stored = (stored << 8) | static_cast<uint32_t>(Bits(8));
    if (truncated_) return Truncated();
    if (stored != adler_) {
      return Status::Error(StatusCode::kDataLoss,
                           "zlib: Adler-32 mismatch (stored %08x, computed %08x)", stored, adler_);
    }
    return Status::Ok();
  }

 private:
  Status Truncated() const {
    return Status::Error(StatusCode::kDataLoss, "zlib: compressed stream is truncated");
  }

  int NextByte() {
    while (pos_ == size_) {
      size_ = source_.Next(&data_);
      pos_ = 0;
      if (size_ == 0) {
        truncated_ = true;
        return 0;
      }
    }
    return data_[pos_++];
  }

  // Next n bits (n <= 16), least significant first. Past the end it returns zeros and sets
  // truncated_, which callers check before using anything decoded from them.
  int Bits(int n) {
    while (bit_count_ < n) {
      bit_buffer_ |= static_cast<uint32_t>(NextByte()) << bit_count_;
      bit_count_ += 8;
    }
    const int value = static_cast<int>(bit_buffer_ & ((1u << n) - 1));
    bit_buffer_ >>= n;
    bit_count_ -= n;
    return value;
  }

  // Returns the decoded symbol, or -1 for a code not in the table (also when truncated).
  int Decode(const Huffman& h) {
    int code = 0, first = 0, index = 0;
    for (int len = 1; len <= kMaxBits; ++len) {
      code |= Bits(1);
      if (truncated_) return -1;
      const int count = h.count[len];
      if (code - count < first) return h.symbol[index + (code - first)];
      index += count;
      first = (first + count) << 1;
      code <<= 1;
    }
    return -1;
  }

  Status Put(uint8_t byte) {
    ring_[total_ & (kRing - 1)] = byte;
    ++total_;
    if (total_ - flushed_ == kWindow) return Flush();
    return Status::Ok();
  }

  // Hands everything not yet written to the sink. flushed_ is a multiple of kWindow, so the
  // pending bytes never wrap around the ring.
  Status Flush() {
    const size_t n = total_ - flushed_;
    if (n == 0) return Status::Ok();
    const uint8_t* start = ring_ + (flushed_ & (kRing - 1));
    adler_ = Adler32(start, n, adler_);
    flushed_ = total_;
    return sink_.Write(start, n);
  }

  Status Stored() {
    bit_buffer_ = 0;  // skip to the byte boundary
    bit_count_ = 0;
    const int len = Bits(16), nlen = Bits(16);
    if (truncated_) return Truncated();
    if (len != (~nlen & 0xffff)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "deflate: stored block length does not match its complement");
    }
    for (int i = 0; i < len; ++i) {
      const int byte = NextByte();
      if (truncated_) return Truncated();
      SH_RETURN_IF_ERROR(Put(static_cast<uint8_t>(byte)));
    }
    return Status::Ok();
  }

  Status Codes(const Huffman& lencode, const Huffman& distcode) {
    for (;;) {
      const int symbol = Decode(lencode);
      if (truncated_) return Truncated();
      if (symbol < 0) {
        return Status::Error(StatusCode::kInvalidArgument, "deflate: invalid literal/length code");
      }
      if (symbol < 256) {
        SH_RETURN_IF_ERROR(Put(static_cast<uint8_t>(symbol)));
        continue;
      }
      if (symbol == 256) return Status::Ok();
      const int li = symbol - 257;
      if (li >= 29) {
        return Status::Error(StatusCode::kInvalidArgument, "deflate: invalid length symbol %d",
                             symbol);
      }
      const int length = kLengthBase[li] + Bits(kLengthExtra[li]);
      const int ds = Decode(distcode);
      if (truncated_) return Truncated();
      if (ds < 0 || ds >= 30) {
        return Status::Error(StatusCode::kInvalidArgument, "deflate: invalid distance code");
      }
      const size_t distance = kDistBase[ds] + static_cast<size_t>(Bits(kDistExtra[ds]));
      if (truncated_) return Truncated();
      if (distance > total_) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "deflate: distance %zu reaches before the start of the data",
                             distance);
      }
      for (int i = 0; i < length; ++i) {
        SH_RETURN_IF_ERROR(Put(ring_[(total_ - distance) & (kRing - 1)]));
      }
    }
  }

  Status Fixed() {
    uint8_t lengths[kMaxLitLen];
    int s = 0;
    for (; s < 144; ++s) lengths[s] = 8;
    for (; s < 256; ++s) lengths[s] = 9;
    for (; s < 280; ++s) lengths[s] = 7;
    for (; s < kMaxLitLen; ++s) lengths[s] = 8;
    Huffman lencode, distcode;
    BuildHuffman(lencode, lengths, kMaxLitLen);
    for (s = 0; s < kMaxDist; ++s) lengths[s] = 5;
    BuildHuffman(distcode, lengths, kMaxDist);
    return Codes(lencode, distcode);
  }

  Status Dynamic() {
    const int nlen = Bits(5) + 257, ndist = Bits(5) + 1, ncode = Bits(4) + 4;
    if (truncated_) return Truncated();
    if (nlen > 286 || ndist > 30) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "deflate: dynamic block with %d length or %d distance codes", nlen,
                           ndist);
    }
    uint8_t lengths[kMaxLitLen + kMaxDist] = {};
    for (int i = 0; i < ncode; ++i) lengths[kCodeLengthOrder[i]] = static_cast<uint8_t>(Bits(3));
    if (truncated_) return Truncated();
    Huffman lencode, distcode;
    if (BuildHuffman(lencode, lengths, 19) != 0) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "deflate: incomplete or over-subscribed code-length code");
    }
    int index = 0;
    while (index < nlen + ndist) {
      const int symbol = Decode(lencode);
      if (truncated_) return Truncated();
      if (symbol < 0) {
        return Status::Error(StatusCode::kInvalidArgument, "deflate: invalid code-length code");
      }
      if (symbol < 16) {
        lengths[index++] = static_cast<uint8_t>(symbol);
        continue;
      }
      uint8_t value = 0;
      int repeat = 0;
      if (symbol == 16) {
        if (index == 0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "deflate: repeat of a code length with none before it");
        }
        value = lengths[index - 1];
        repeat = 3 + Bits(2);
      } else if (symbol == 17) {
        repeat = 3 + Bits(3);
      } else {
        repeat = 11 + Bits(7);
      }
      if (truncated_) return Truncated();
      if (index + repeat > nlen + ndist) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "deflate: code lengths run past the end of the table");
      }
      while (repeat-- > 0) lengths[index++] = value;
    }
    if (lengths[256] == 0) {
      return Status::Error(StatusCode::kInvalidArgument, "deflate: no end-of-block code");
    }
    // An incomplete literal/length code is only acceptable as a single code of length 1.
    const int len_err = BuildHuffman(lencode, lengths, nlen);
    if (len_err < 0 || (len_err > 0 && nlen - lencode.count[0] != 1)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "deflate: incomplete or over-subscribed literal/length code");
    }
    const int dist_err = BuildHuffman(distcode, lengths + nlen, ndist);
    if (dist_err < 0 || (dist_err > 0 && ndist - distcode.count[0] != 1)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "deflate: incomplete or over-subscribed distance code");
    }
    return Codes(lencode, distcode);
  }

  ByteSource& source_;
  ByteSink& sink_;
  const uint8_t* data_ = nullptr;
  size_t size_ = 0, pos_ = 0;
  bool truncated_ = false;
  uint32_t bit_buffer_ = 0;
  int bit_count_ = 0;
  size_t total_ = 0, flushed_ = 0;
  uint32_t adler_ = 1;
  uint8_t ring_[kRing];
};

}  // namespace

uint32_t Adler32(const uint8_t* data, size_t size, uint32_t adler) {
  uint32_t a = adler & 0xffff, b = adler >> 16;
  while (size > 0) {
    // 5552 bytes is the longest run before b can overflow 32 bits (zlib's NMAX).
    size_t n = size < 5552 ? size : 5552;
    size -= n;
    while (n-- > 0) {
      a += *data++;
      b += a;
    }
    a %= 65521;
    b %= 65521;
  }
  return (b << 16) | a;
}

Status ZlibInflate(ByteSource& source, ByteSink& sink) {
  static_assert(sizeof(Inflater) < 80 * 1024, "decoder state is meant to fit on the stack");
  Inflater inflater(source, sink);
  return inflater.Run();
}

}  // namespace sh::hal
