#include "neuflow/flow/flow_index.hpp"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <utility>

namespace neuflow::flow {
namespace {

TEST(FlowIndex, OneHeaderForEveryWriter) {
  EXPECT_EQ(flow_index_header(), "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source\n");
  // `file` is column kFlowIndexFileColumn (from 0).
  std::size_t start = 0;
  for (std::size_t column = 0; column < kFlowIndexFileColumn; ++column) start = kFlowIndexColumns.find(',', start) + 1;
  EXPECT_EQ(kFlowIndexColumns.substr(start, 5), "file,");
}

TEST(FlowIndex, RowWritesUnknownTimestampsAndSourcesAsEmptyFields) {
  EXPECT_EQ(flow_index_row({3, 7, 8, 70, 80, "flow_3.flo"}), "3,7,8,70,80,flow_3.flo,,\n");
  EXPECT_EQ(flow_index_row({0, 0, 1, std::nullopt, std::nullopt, "a.npy"}), "0,0,1,,,a.npy,,\n");
  EXPECT_EQ(flow_index_row({0, 0, 1, std::nullopt, 5, "a.npy", "x.png", ""}), "0,0,1,,5,a.npy,x.png,\n");
}

TEST(FlowIndex, TextFieldsAreQuotedOnlyWhenTheyNeedIt) {
  const std::pair<std::string_view, std::string_view> cases[] = {
      {"plain name.flo", "plain name.flo"}, {"x,y.flo", "\"x,y.flo\""}, {"say \"hi\"", "\"say \"\"hi\"\"\""},
      {"line\nbreak", "\"line\nbreak\""},   {"cr\r", "\"cr\r\""},
  };
  for (const auto& [text, field] : cases) EXPECT_EQ(csv_field(text), field) << text;
  EXPECT_EQ(flow_index_row({1, 1, 2, 10, 20, "a,b.flo", "c\"d.png", "e.png"}),
            "1,1,2,10,20,\"a,b.flo\",\"c\"\"d.png\",e.png\n");
}

}  // namespace
}  // namespace neuflow::flow
