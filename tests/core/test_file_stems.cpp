// output_file_stems: every stem a valid, distinct file name, whatever the part names.
#include "core/io/file_stems.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

namespace loom {
namespace {

TEST(FileStems, OrdinaryNamesAreKept) {
  EXPECT_EQ(output_file_stems({"spar-front", "rib_1", "box.v2"}),
            (std::vector<std::string>{"spar-front", "rib_1", "box.v2"}));
}

TEST(FileStems, OddCharactersEmptyAndDotNamesBecomeSafe) {
  const auto s = output_file_stems({"../../etc/passwd", "", "a b\nc", ".", "..", "ü"});
  EXPECT_EQ(s[0], "_.._.._etc_passwd");
  EXPECT_EQ(s[1], "part");
  EXPECT_EQ(s[2], "a_b_c");
  EXPECT_EQ(s[3], "_.");
  EXPECT_EQ(s[4], "_..");
  EXPECT_EQ(s[5], "__");  // two UTF-8 bytes
}

TEST(FileStems, DuplicatesGetSuffixes) {
  EXPECT_EQ(output_file_stems({"a/b", "a_b", "a:b", "a_b_2"}),
            (std::vector<std::string>{"a_b", "a_b_2", "a_b_3", "a_b_2_2"}));
}

TEST(FileStems, LongNamesAreCutAndStayDistinct) {
  const std::string a(100000, 'x'), b = a + "y", c(kMaxFileStemLength, 'z');
  const auto s = output_file_stems({a, b, c});
  EXPECT_EQ(s[0].size(), kMaxFileStemLength);
  EXPECT_EQ(s[1].size(), kMaxFileStemLength);
  EXPECT_NE(s[0], s[1]);  // the hash of the whole name tells them apart
  EXPECT_EQ(s[2], c);     // at the limit: kept as it is
  EXPECT_EQ(s[0].substr(0, 10), std::string(10, 'x'));
}

TEST(FileStems, EmptyInput) { EXPECT_TRUE(output_file_stems({}).empty()); }

}  // namespace
}  // namespace loom
