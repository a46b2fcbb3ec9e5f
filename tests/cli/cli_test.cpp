// Every tool: --help lists each option with its default, --version answers, a bad option exits 1 with
// `tool: ...`, and the options its doc's "## Usage" section names are exactly the options its parser has
// (the parser generates --help, so a documented flag that nothing parses, or an undocumented one, fails).
#include "test_support.h"

#include <fstream>
#include <regex>
#include <set>

namespace temporal {
namespace {

const char* const kTools[] = {"compare", "render-gbuffer", "upsample-st", "filter-phlm", "morph-120hz"};

std::set<std::string> long_options(const std::string& text) {
  std::set<std::string> options;
  static const std::regex option(R"((^|[^A-Za-z0-9-])(--[a-z][a-z0-9-]*))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), option); it != std::sregex_iterator(); ++it)
    options.insert((*it)[2].str());
  return options;
}

// The text of the "## Usage" section of docs/<tool>.md (up to the next "## " heading).
std::string usage_section(const std::string& tool) {
  std::ifstream in(test::source_dir() / "docs" / (tool + ".md"));
  std::string line, section;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) {
      if (inside) break;
      inside = line.rfind("## Usage", 0) == 0;
      continue;
    }
    if (inside) section += line + "\n";
  }
  return section;
}

class ToolCli : public ::testing::TestWithParam<const char*> {};

TEST_P(ToolCli, HelpVersionAndBadOptions) {
  const std::string tool = GetParam();
  const std::string exe = test::tool_path(tool).string();
  std::string out;
  ASSERT_EQ(test::run_command(exe + " --help", &out), 0) << out;
  EXPECT_NE(out.find("--threads"), std::string::npos) << out;
  EXPECT_NE(out.find("Exit codes"), std::string::npos) << out;
  ASSERT_EQ(test::run_command(exe + " --version", &out), 0) << out;
  EXPECT_EQ(out.rfind(tool + " ", 0), 0u) << out;
  EXPECT_EQ(test::run_command(exe + " --no-such-option 2", &out), 1) << out;
  EXPECT_EQ(out.rfind(tool + ": ", 0), 0u) << out;
  EXPECT_EQ(test::run_command(exe + " --threads -3", &out), 1) << out;
}

TEST_P(ToolCli, DocumentedOptionsAreExactlyTheParsedOptions) {
  const std::string tool = GetParam();
  std::string help;
  ASSERT_EQ(test::run_command(test::tool_path(tool).string() + " --help", &help), 0);
  const std::string usage = usage_section(tool);
  ASSERT_FALSE(usage.empty()) << "docs/" << tool << ".md has no '## Usage' section";
  std::set<std::string> in_help = long_options(help), in_docs = long_options(usage);
  // Options every tool shares are documented once, in docs/cli.md.
  for (const char* common : {"--help", "--version", "--threads", "--verbose"}) {
    in_help.erase(common);
    in_docs.erase(common);
  }
  for (const auto& o : in_docs) EXPECT_TRUE(in_help.count(o)) << "docs/" << tool << ".md documents " << o << ", which " << tool << " does not parse";
  for (const auto& o : in_help) EXPECT_TRUE(in_docs.count(o)) << tool << " parses " << o << ", which docs/" << tool << ".md (## Usage) does not document";
}

INSTANTIATE_TEST_SUITE_P(AllTools, ToolCli, ::testing::ValuesIn(kTools), [](const auto& param_info) {
  std::string name = param_info.param;
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
});

}  // namespace
}  // namespace temporal
