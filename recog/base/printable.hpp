// Bytes from files, blobs and clients, made safe to put into a message: a corrupt table's model
// name or a config line with a byte-order mark must not write control characters or stray
// UTF-8 into a log or a terminal.
#pragma once

#include <cstddef>

namespace sh {

// Enough for a 31-character name with every byte escaped.
inline constexpr size_t kPrintableNameBytes = 4 * 31 + 4;

// Writes `raw` (up to `raw_length` bytes, stopping at a NUL) into `out` as printable ASCII:
// bytes 0x20..0x7E as they are except '\', which becomes "\\", every other byte as "\xNN". Text
// that does not fit ends in "...". Returns `out`, always NUL-terminated (out_size > 0).
const char* Printable(const char* raw, size_t raw_length, char* out, size_t out_size);

// Enough for a 31-character name as the contents of a JSON string, every byte escaped.
inline constexpr size_t kJsonNameBytes = 6 * 31 + 4;

// The same for the contents of a JSON string literal: '"' and '\' escaped with a backslash,
// every byte outside 0x20..0x7E as "\u00NN", so that a model name such as `cu"be\x` or one
// holding control characters keeps a JSON line valid. Text that does not fit ends in "...".
const char* JsonEscaped(const char* raw, size_t raw_length, char* out, size_t out_size);

}  // namespace sh
