#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "convert/natural_sort.hpp"

namespace neuflow::cli {
namespace {

TEST(NaturalSort, NumbersCompareByValue) {
  EXPECT_TRUE(natural_less("frame2", "frame10"));
  EXPECT_FALSE(natural_less("frame10", "frame2"));
  EXPECT_TRUE(natural_less("frame9.png", "frame10.png"));
  EXPECT_TRUE(natural_less("frame007", "frame10"));
}

TEST(NaturalSort, SortsAShuffledSequence) {
  std::vector<std::string> names = {"frame10.png", "frame1.png",  "frame100.png",
                                    "frame2.png",  "frame11.png", "frame3.png"};
  std::sort(names.begin(), names.end(), [](const auto& a, const auto& b) { return natural_less(a, b); });
  EXPECT_EQ(names, (std::vector<std::string>{"frame1.png", "frame2.png", "frame3.png", "frame10.png", "frame11.png",
                                             "frame100.png"}));
}

TEST(NaturalSort, TimestampsLongerThanAnyIntegerType) {
  EXPECT_TRUE(natural_less("1684437740861809471123.jpg", "1684437740861809471124.jpg"));
  EXPECT_TRUE(natural_less("999999999999999999999.jpg", "1000000000000000000000.jpg"));
}

TEST(NaturalSort, PrefixesAndTextCompareAsUsual) {
  EXPECT_TRUE(natural_less("a", "a1"));
  EXPECT_TRUE(natural_less("a1", "b"));
  EXPECT_TRUE(natural_less("cam1_frame9", "cam2_frame1"));
  EXPECT_FALSE(natural_less("same", "same"));
}

TEST(NaturalSort, LeadingZerosDistinctButOrderedStrictly) {
  // Equal value, different text: exactly one order holds, so sorting is deterministic.
  EXPECT_NE(natural_less("img01", "img1"), natural_less("img1", "img01"));
  EXPECT_TRUE(natural_less("img01", "img2"));
  EXPECT_TRUE(natural_less("img1", "img02"));
}

}  // namespace
}  // namespace neuflow::cli
