#include "recog/base/printable.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace sh {
namespace {

std::string Show(const char* raw, size_t raw_length, size_t out_size = 64) {
  char out[256];
  return Printable(raw, raw_length, out, out_size);
}

TEST(Printable, AsciiPassesControlAndHighBytesAreEscaped) {
  EXPECT_EQ(Show("cube", 4), "cube");
  EXPECT_EQ(Show("a\tb\x1b[2J", 7), "a\\x09b\\x1B[2J");
  EXPECT_EQ(Show("\xEF\xBB\xBFnode_id", 10), "\\xEF\\xBB\\xBFnode_id");
  EXPECT_EQ(Show("back\\slash", 10), "back\\\\slash");
}

TEST(Printable, StopsAtNulOrLength) {
  EXPECT_EQ(Show("abc\0def", 7), "abc");
  EXPECT_EQ(Show("abcdef", 3), "abc");
  // A name field with no NUL: only its bytes.
  const char field[4] = {'w', 'x', 'y', 'z'};
  EXPECT_EQ(Show(field, sizeof(field)), "wxyz");
}

TEST(Printable, CutsWholeEscapesAndMarksTheCut) {
  EXPECT_EQ(Show("abcdefghi", 9, 10), "abcdefghi");  // fits exactly
  EXPECT_EQ(Show("abcdefghij", 10, 10), "abcdef...");
  EXPECT_EQ(Show("ab\x01\x02\x03", 5, 10), "ab\\x01...");  // never half an escape
  char out[4];
  EXPECT_STREQ(Printable("abcdef", 6, out, sizeof(out)), "abc");
  EXPECT_STREQ(Printable("abcdef", 6, out, 1), "");
}

TEST(JsonEscaped, QuotesBackslashesAndControlBytesKeepAJsonStringValid) {
  char out[kJsonNameBytes];
  EXPECT_STREQ(JsonEscaped("cube", 4, out, sizeof(out)), "cube");
  EXPECT_STREQ(JsonEscaped("cu\"be\\x", 7, out, sizeof(out)), "cu\\\"be\\\\x");
  EXPECT_STREQ(JsonEscaped("a\nb\x1b\xff", 5, out, sizeof(out)), "a\\u000ab\\u001b\\u00ff");
  // The longest name, every byte escaped, fits whole.
  const std::string quotes(31, '\x01');
  EXPECT_EQ(std::string(JsonEscaped(quotes.c_str(), 31, out, sizeof(out))).size(), 31u * 6);
}

}  // namespace
}  // namespace sh
