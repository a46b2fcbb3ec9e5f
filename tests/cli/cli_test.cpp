// Every tool: --help lists each option with its default, --version answers, a bad option exits 1 with
// `tool: ...`, and the options its doc's "## Usage" section names are exactly the options its parser has
// (the parser generates --help, so a documented flag that nothing parses, or an undocumented one, fails).
#include "temporal/io/exr.h"
#include "temporal/core/image.h"

#include "test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>
#include <utility>
#include <vector>

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

// Issue 26, "Exit codes that say fine": empty option values (`--flag=`) and infinite or overflowing ones are usage
// errors (exit 1) naming the option, before any file is read (the inputs named here do not exist: an input error,
// exit 2, would mean the options were accepted).
TEST(OptionValues, EmptyInfiniteAndOverflowingValuesAreUsageErrorsNamingTheOption) {
  const std::string seq = " --input in.####.exr --gbuffer g.####.exr --out o.####.exr";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"morph-120hz" + seq, "--distortion-low="},
      {"morph-120hz" + seq, "--distortion-low inf"},
      {"morph-120hz" + seq, "--snap-threshold 1e300"},
      {"morph-120hz" + seq, "--ppd 1e-40"},
      {"morph-120hz" + seq, "--fps 1e-40"},
      {"compare --reference r.####.exr t.####.exr", "--sheet-frame="},
      {"compare --reference r.####.exr t.####.exr", "--ppd 1e30"},
      {"compare --reference r.####.exr t.####.exr", "--exposure 1e10"},
      {"compare --reference r.####.exr t.####.exr", "--fail-psnr inf"},
      {"upsample-st" + seq, "--lock-luma-change="},
      {"upsample-st" + seq, "--sigma-depth 1e-40"},
      {"upsample-st" + seq, "--max-history-weight 1e30"},
      {"render-gbuffer scene.glb --out o", "--ssao-radius inf"},
      {"render-gbuffer scene.glb --out o", "--shadow-bias -inf"},
      {"render-gbuffer scene.glb --out o", "--ssao-radius="},
      {"render-gbuffer scene.glb --out o", "--fps 1e-45"},
      {"filter-phlm" + seq, "--p-init 1e38"},
      {"filter-phlm" + seq, "--trace-factor 1e-40"},
      {"filter-phlm" + seq, "--ema-depth-tolerance inf"},
  };
  const std::string dir = test::scratch_dir("option_values").string();
  for (const auto& [command, option] : cases) {
    const std::string tool = command.substr(0, command.find(' '));
    const std::string args = command.substr(command.find(' '));
    std::string out;
    EXPECT_EQ(test::run_command("cd " + dir + " && " + test::tool_path(tool).string() + args + " " + option, &out), 1)
        << tool << " " << option << "\n" << out;
    const std::string flag = option.substr(0, option.find_first_of(" ="));
    EXPECT_NE(out.find(flag), std::string::npos) << tool << " " << option << "\n" << out;
    EXPECT_EQ(out.rfind(tool + ": ", 0), 0u) << out;
  }
}

// Issue 21: `--layer` is one rule (select_layers, docs/conventions.md "Layers") in every tool. One multi-layer
// sequence (render-gbuffer's shade: R,G,B, direct.R,G,B, ssao.Y, ...) goes through all four tools with the same
// selections; each writes (or compares) exactly the channels the rule selects, and each refuses a missing layer
// with exit 2 naming it. What differs is only what a tool can take: filter-phlm 1 or 3 channels, morph-120hz 3.
// A TEMPORAL_ISA the run cannot honour is said on stderr (the user asked for a level: issue 27), whatever the
// tool does next; --verbose names the level the CPU kernels run at. The missing input makes the run end at once.
TEST(IsaNote, AnUnusableTemporalIsaIsSaidAndVerboseNamesTheLevel) {
  std::string out;
  const std::string exe = test::tool_path("compare").string();
  EXPECT_EQ(test::run_command("TEMPORAL_ISA=v9 " + exe + " --reference no/r.####.exr no/t.####.exr --verbose", &out), 2)
      << out;
  EXPECT_NE(out.find("compare: note: TEMPORAL_ISA=v9 "), std::string::npos) << out;
  EXPECT_NE(out.find("compare: CPU kernels: "), std::string::npos) << out;
  EXPECT_EQ(test::run_command("env -u TEMPORAL_ISA " + exe + " --reference no/r.####.exr no/t.####.exr", &out), 2)
      << out;
  EXPECT_EQ(out.find("TEMPORAL_ISA"), std::string::npos) << out;  // nothing asked, nothing said
}

TEST(LayerRule, EveryToolSelectsTheSameChannels) {
  const auto dir = test::scratch_dir("layer-rule");
  const std::string d = dir.string();
  std::string out;
  ASSERT_EQ(test::run_command(test::tool_path("render-gbuffer").string() + " " +
                                  (test::source_dir() / "assets" / "scenes" / "walkers.glb").string() + " --out " + d +
                                  " --size 64x48 --factor 2 --frames 0-2 --outputs gbuffer,shade",
                              &out), 0) << out;
  const std::string shade = d + "/shade.####.exr", gbuffer = d + "/gbuffer.####.exr";
  auto first = read_exr(d + "/shade.0000.exr");
  ASSERT_TRUE(first) << first.error().message;
  ASSERT_TRUE(first->has_channel("direct.R") && first->has_channel("ssao.Y")) << "the shade has no direct or ssao";

  auto tool = [](const char* name) { return test::tool_path(name).string(); };
  // The channels of `layer` in a tool's first output, or the command's exit code as a string.
  auto channels_of = [&](const std::string& command, const std::string& output) -> std::vector<std::string> {
    std::string text;
    const int code = test::run_command(command, &text);
    if (code != 0) return {"exit " + std::to_string(code) + ": " + text};
    auto img = read_exr(output);
    if (!img) return {img.error().message};
    std::vector<std::string> names;
    for (const auto& c : img->channel_names())
      if (c.rfind("debug.", 0) != 0) names.push_back(c);
    std::sort(names.begin(), names.end());
    return names;
  };
  auto sorted = [](std::vector<std::string> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  for (const std::string layer : {"rgb", "direct", "ssao", "ssao.Y"}) {
    auto expected = select_layers(*first, layer, "shade.0000.exr");
    ASSERT_TRUE(expected) << layer;
    const std::string o = d + "/" + (layer == "ssao.Y" ? std::string("ssaoY") : layer);
    EXPECT_EQ(channels_of(tool("upsample-st") + " --input " + shade + " --gbuffer " + gbuffer + " --method spatial --out " +
                              o + "-up.####.exr --layer " + layer, o + "-up.0000.exr"),
              sorted(*expected)) << "upsample-st --layer " << layer;
    EXPECT_EQ(channels_of(tool("filter-phlm") + " --input " + shade + " --method fxaa --out " + o +
                              "-filter.####.exr --layer " + layer, o + "-filter.0000.exr"),
              sorted(*expected)) << "filter-phlm --layer " << layer;
    if (expected->size() == 3) {
      EXPECT_EQ(channels_of(tool("morph-120hz") + " --input " + shade + " --fps 40 --method repeat --out " + o +
                                "-morph.####.exr --layer " + layer, o + "-morph.0000.exr"),
                sorted(*expected)) << "morph-120hz --layer " << layer;
    }
    ASSERT_EQ(test::run_command(tool("compare") + " --reference " + shade + " " + shade + " --json " + o + ".json --layer " +
                                    layer, &out), 0) << out;
    std::ifstream json(o + ".json");
    EXPECT_EQ(nlohmann::json::parse(json)["channels"].get<std::vector<std::string>>(), *expected)
        << "compare --layer " << layer;
  }
  // A comma list: the same channels wherever the tool takes that many.
  EXPECT_EQ(channels_of(tool("upsample-st") + " --input " + shade + " --gbuffer " + gbuffer + " --method spatial --out " + d +
                            "/list-up.####.exr --layer direct,ssao", d + "/list-up.0000.exr"),
            (std::vector<std::string>{"direct.B", "direct.G", "direct.R", "ssao.Y"}));
  EXPECT_EQ(test::run_command(tool("compare") + " --reference " + shade + " " + shade + " --layer direct,ssao", &out), 0) << out;
  EXPECT_EQ(test::run_command(tool("filter-phlm") + " --input " + shade + " --method fxaa --out " + d +
                                  "/list-f.####.exr --layer direct,ssao", &out), 1) << out;  // 4 channels: 1 or 3
  EXPECT_EQ(test::run_command(tool("morph-120hz") + " --input " + shade + " --fps 40 --method repeat --out " + d +
                                  "/list-m.####.exr --layer ssao", &out), 1) << out;  // 1 channel: 3
  // A missing layer: exit 2 from every tool, naming it.
  const std::vector<std::string> missing = {
      tool("upsample-st") + " --input " + shade + " --gbuffer " + gbuffer + " --method spatial --out " + d + "/x.####.exr",
      tool("filter-phlm") + " --input " + shade + " --method fxaa --out " + d + "/x.####.exr",
      tool("morph-120hz") + " --input " + shade + " --fps 40 --method repeat --out " + d + "/x.####.exr",
      tool("compare") + " --reference " + shade + " " + shade};
  for (const auto& command : missing) {
    EXPECT_EQ(test::run_command(command + " --layer albdo", &out), 2) << command << "\n" << out;
    EXPECT_NE(out.find("no layer 'albdo' (have: rgb, direct, "), std::string::npos) << out;
  }
}

}  // namespace
}  // namespace temporal
