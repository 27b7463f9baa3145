// The tools' reports: the one table writer behind every text, Markdown and CSV table
// (against what a CSV reader and a Markdown renderer expect), the stress suite's summary,
// and the builder names parsed once into their kinds.
#include <gtest/gtest.h>

#include <sstream>

#include "adapters/bench/stress.h"
#include "adapters/bench/table.h"
#include "adapters/builder_registry.h"

namespace kmbvh {
namespace {

Table small_table() {
  Table t({{"name", Align::Left}, {"value"}});
  t.add_row({"a", "1"});
  t.add_row({"longer", "12345"});
  return t;
}

TEST(Table, TextPadsEachColumnToItsWidestCell) {
  EXPECT_EQ(small_table().text(),
            "name    value\n"
            "a           1\n"
            "longer  12345\n");
}

TEST(Table, MarkdownHasARuleSayingTheAlignment) {
  EXPECT_EQ(small_table().markdown(),
            "| name | value |\n"
            "|---|---:|\n"
            "| a | 1 |\n"
            "| longer | 12345 |\n");
}

TEST(Table, MarkdownEscapesPipesAndFlattensLineBreaks) {
  Table t({{"x", Align::Left}});
  t.add_row({"a|b\nc"});
  EXPECT_EQ(t.markdown(), "| x |\n|---|\n| a\\|b c |\n");
}

// RFC 4180, read back the way a spreadsheet reads it.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
  bool quoted = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') rows.back().back() += text[++i];
      else if (c == '"') quoted = false;
      else rows.back().back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().emplace_back();
    } else if (c == '\n') {
      rows.emplace_back(1);
    } else {
      rows.back().back() += c;
    }
  }
  if (rows.back().size() == 1 && rows.back()[0].empty()) rows.pop_back();
  return rows;
}

TEST(Table, CsvQuotesOnlyWhatNeedsIt) {
  Table t({{"builder"}, {"note"}, {"ms"}});
  t.add_row({"kmeans Q2", "a, b", "1.5"});
  t.add_row({"ploc r=8", "say \"hi\"\nthere", ""});
  const std::string csv = t.csv();
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "builder,note,ms");
  EXPECT_NE(csv.find("kmeans Q2,\"a, b\",1.5\n"), std::string::npos) << csv;
  const auto rows = parse_csv(csv);
  ASSERT_EQ(rows.size(), 3u) << csv;
  EXPECT_EQ(rows[2], (std::vector<std::string>{"ploc r=8", "say \"hi\"\nthere", ""}));
}

TEST(Table, RefusesARowOfTheWrongWidth) {
  Table t({{"a"}, {"b"}});
  EXPECT_THROW(t.add_row({"1"}), std::invalid_argument);
  EXPECT_THROW(t.add_row({"1", "2", "3"}), std::invalid_argument);
  EXPECT_THROW(Table(std::vector<Column>{}), std::invalid_argument);
}

TEST(Table, WriteTextFileNamesAFileItCannotWrite) {
  try {
    write_text_file("/nonexistent-folder/table.md", "x");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/table.md"), std::string::npos) << e.what();
  }
}

TEST(StressReport, SummaryHasACaseARowAndAFailureInBold) {
  StressRow ok, failed;
  ok.scene = failed.scene = "needles";
  ok.triangles = failed.triangles = 500;
  ok.builder = "sweep-sah";
  ok.outcome = StressOutcome::Ok;
  ok.sah_over_sweep = 1.0;
  failed.builder = "kmeans Q2";
  failed.outcome = StressOutcome::Mismatch;
  const std::string md = stress_summary_table({{ok, failed}}).markdown();
  EXPECT_NE(md.find("| case | triangles | sweep-sah | kmeans Q2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| needles | 500 | 1.00 | **mismatch** |"), std::string::npos) << md;
  EXPECT_EQ(to_json(failed)["outcome"], "mismatch");
}

TEST(BuilderKinds, EveryNameParsesToItsKindAndBack) {
  ASSERT_EQ(builder_kinds().size(), 10u);
  for (const BuilderKind kind : builder_kinds()) {
    EXPECT_EQ(builder_kind(to_string(kind)), kind);
    EXPECT_EQ(parse_builder(to_string(kind)).builder, kind) << to_string(kind);
  }
  EXPECT_EQ(parse_builder("Q4").builder, BuilderKind::Kmeans);
  EXPECT_EQ(parse_builder("kmeans:q4").preset, "Q4");
  EXPECT_FALSE(builder_kind("kmeans:Q2"));
  EXPECT_FALSE(builder_kind("Embree-Low"));
  EXPECT_THROW(parse_builder("nonsense"), std::invalid_argument);
  EXPECT_THROW(parse_builder("lbvh:Q2"), std::invalid_argument);  // only k-means takes a preset
  EXPECT_TRUE(is_embree_builder(BuilderKind::EmbreeMedium));
  EXPECT_FALSE(is_embree_builder(BuilderKind::Kmeans));
  EXPECT_TRUE(is_binary_builder(BuilderKind::Ploc));
  EXPECT_FALSE(is_binary_builder(BuilderKind::SweepSah));
  EXPECT_EQ(all_builders().front().label(), "sweep-sah");
}

}  // namespace
}  // namespace kmbvh
