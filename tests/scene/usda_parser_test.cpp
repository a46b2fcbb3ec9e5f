// The .usda parser (libtemporal/src/scene/usda_parser.cpp) on small hand-written layers: every value form,
// metadata, list ops, time samples, connections and relationships read as written; malformed text gives
// `file:line:column: what is wrong` at the position counted by hand.
#include "test_support.h"

#include "usd_layer.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace temporal::usd {
namespace {

std::unique_ptr<Layer> parse_ok(const std::string& text, const std::string& path = "/scenes/root.usda") {
  auto l = parse_usda(text, path);
  EXPECT_TRUE(l) << (l ? "" : l.error().file + ": " + l.error().message);
  return l ? std::move(*l) : std::make_unique<Layer>();
}

const char* const kLayer = R"(#usda 1.0
(
    "a layer comment"
    defaultPrim = "World"
    upAxis = "Z"
    metersPerUnit = 0.01
    timeCodesPerSecond = 30
    subLayers = [
        @./sub.usda@ (offset = 10; scale = 2),
        @other.usda@
    ]
)

def Xform "World" (
    kind = "component"
    prepend references = [@./a.usda@</A> (offset = 5), </Internal>]
    variants = {
        string shading = "red"
    }
    prepend variantSets = ["shading", "lod"]
    prepend apiSchemas = ["MaterialBindingAPI"]
    inherits = </_class>
)
{
    float3 a = (1, -2.5, 3e2)
    double b = -inf
    point3f[] pts = [(0, 0, 0), (1, .5, 0),]
    matrix4d m = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (4, 5, 6, 1) )
    string s = "a \"quoted\"\nline"
    string t = """multi
line"""
    token[] toks = ["x", 'y']
    asset tex = @textures/wood.png@
    bool flag = true
    int[] blocked = None
    int[] empty = []
    quatf q.timeSamples = {
        2: (1, 0, 0, 0),
        1: (0, 1, 0, 0),
        2: (0, 0, 1, 0),
    }
    color3f inputs:c.connect = </World/Shader.outputs:rgb>
    rel target = <Child>
    prepend rel material:binding = </Looks/M>
    float2 st = (0.5, 0.25) (
        interpolation = "faceVarying"
        elementSize = 2
        customData = {
            dictionary nested = {
                int x = 1
            }
        }
    )
    // a C++-style comment and # a shell-style one
    def Mesh "Child" {}
    variantSet "shading" = {
        "red" (
            kind = "subcomponent"
        ) {
            color3f c = (1, 0, 0)
        }
        "blue" {
        }
    }
}
)";

TEST(UsdaParser, ReadsLayerMetadataAndSubLayers) {
  auto l = parse_ok(kLayer);
  EXPECT_EQ(l->default_prim, "World");
  EXPECT_EQ(l->token("upAxis", "Y"), "Z");
  EXPECT_DOUBLE_EQ(l->number("metersPerUnit", 1.0), 0.01);
  EXPECT_DOUBLE_EQ(l->number("timeCodesPerSecond", 24.0), 30.0);
  EXPECT_DOUBLE_EQ(l->number("startTimeCode", -1.0), -1.0) << "absent metadata gives the fallback";
  ASSERT_EQ(l->sublayers.size(), 2u);
  EXPECT_EQ(l->sublayers[0].asset, "./sub.usda");
  EXPECT_EQ(l->sublayers[0].resolved, "/scenes/sub.usda");
  EXPECT_DOUBLE_EQ(l->sublayers[0].offset.offset, 10.0);
  EXPECT_DOUBLE_EQ(l->sublayers[0].offset.scale, 2.0);
  EXPECT_EQ(l->sublayers[1].resolved, "/scenes/other.usda");
  EXPECT_DOUBLE_EQ(l->sublayers[1].offset.scale, 1.0);
}

TEST(UsdaParser, ReadsPrimMetadataAndCompositionArcs) {
  auto l = parse_ok(kLayer);
  const PrimSpec* w = l->prim_at("/World");
  ASSERT_NE(w, nullptr);
  EXPECT_EQ(w->specifier, Specifier::Def);
  EXPECT_EQ(w->type_name, "Xform");
  ASSERT_NE(w->meta("kind"), nullptr);
  EXPECT_EQ(w->meta("kind")->text, std::vector<std::string>{"component"});
  ASSERT_EQ(w->references.prepended.size(), 2u);
  EXPECT_FALSE(w->references.is_explicit);
  EXPECT_EQ(w->references.prepended[0].resolved, "/scenes/a.usda");
  EXPECT_EQ(w->references.prepended[0].prim, "/A");
  EXPECT_DOUBLE_EQ(w->references.prepended[0].offset.offset, 5.0);
  EXPECT_TRUE(w->references.prepended[1].asset.empty()) << "internal reference";
  EXPECT_EQ(w->references.prepended[1].prim, "/Internal");
  ASSERT_NE(w->variant_selection("shading"), nullptr);
  EXPECT_EQ(*w->variant_selection("shading"), "red");
  EXPECT_EQ(w->variant_set_names.prepended, (std::vector<std::string>{"shading", "lod"}));
  EXPECT_EQ(w->api_schemas.prepended, std::vector<std::string>{"MaterialBindingAPI"});
  EXPECT_TRUE(w->inherits.is_explicit);
  EXPECT_EQ(w->inherits.explicit_items, std::vector<std::string>{"/_class"});
}

TEST(UsdaParser, ReadsEveryValueForm) {
  auto l = parse_ok(kLayer);
  const PrimSpec* w = l->prim_at("/World");
  ASSERT_NE(w, nullptr);
  auto value = [&](const char* name) -> const Value& {
    const PropertySpec* p = w->property(name);
    EXPECT_NE(p, nullptr) << name;
    static const Value none;
    return p ? p->default_value : none;
  };
  EXPECT_EQ(value("a").numbers, (std::vector<double>{1.0, -2.5, 300.0}));
  EXPECT_EQ(value("a").tuple, 3);
  EXPECT_FALSE(value("a").array);
  EXPECT_TRUE(std::isinf(value("b").numbers.at(0)) && value("b").numbers[0] < 0);
  EXPECT_EQ(value("pts").numbers, (std::vector<double>{0, 0, 0, 1, 0.5, 0}));
  EXPECT_EQ(value("pts").size(), 2u) << "trailing comma accepted";
  EXPECT_EQ(value("m").tuple, 16);
  EXPECT_EQ(value("m").numbers[12], 4.0) << "matrix values in file order (rows)";
  EXPECT_EQ(value("s").text.at(0), "a \"quoted\"\nline");
  EXPECT_EQ(value("t").text.at(0), "multi\nline");
  EXPECT_EQ(value("toks").text, (std::vector<std::string>{"x", "y"}));
  EXPECT_EQ(value("tex").kind, Value::Kind::Asset);
  EXPECT_EQ(value("tex").resolved.at(0), "/scenes/textures/wood.png");
  EXPECT_EQ(value("flag").numbers, std::vector<double>{1.0});
  EXPECT_TRUE(value("blocked").is_none());
  EXPECT_EQ(value("empty").kind, Value::Kind::Number) << "an empty array takes its declared type";
  EXPECT_TRUE(value("empty").numbers.empty());
}

TEST(UsdaParser, ReadsTimeSamplesConnectionsRelationshipsAndPropertyMetadata) {
  auto l = parse_ok(kLayer);
  const PrimSpec* w = l->prim_at("/World");
  ASSERT_NE(w, nullptr);
  const PropertySpec* q = w->property("q");
  ASSERT_NE(q, nullptr);
  ASSERT_EQ(q->time_samples.size(), 2u) << "sorted by time, the later of two samples at one time wins";
  EXPECT_EQ(q->time_samples[0].first, 1.0);
  EXPECT_EQ(q->time_samples[0].second.numbers, (std::vector<double>{0, 1, 0, 0}));
  EXPECT_EQ(q->time_samples[1].second.numbers, (std::vector<double>{0, 0, 1, 0}));
  const PropertySpec* c = w->property("inputs:c");
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->connections.explicit_items, std::vector<std::string>{"/World/Shader.outputs:rgb"});
  const PropertySpec* t = w->property("target");
  ASSERT_NE(t, nullptr);
  EXPECT_TRUE(t->relationship);
  EXPECT_EQ(t->targets.explicit_items, std::vector<std::string>{"/World/Child"}) << "relative to the owning prim";
  const PropertySpec* b = w->property("material:binding");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->targets.prepended, std::vector<std::string>{"/Looks/M"});
  const PropertySpec* st = w->property("st");
  ASSERT_NE(st, nullptr);
  ASSERT_EQ(st->metadata.size(), 3u);
  EXPECT_EQ(st->metadata[0].first, "interpolation");
  EXPECT_EQ(st->metadata[0].second.text.at(0), "faceVarying");
  EXPECT_EQ(st->metadata[1].second.numbers, std::vector<double>{2.0});
  const Value* nested = st->metadata[2].second.find("nested");
  ASSERT_NE(nested, nullptr);
  ASSERT_NE(nested->find("x"), nullptr);
  EXPECT_EQ(nested->find("x")->numbers, std::vector<double>{1.0});
}

TEST(UsdaParser, ReadsChildrenAndVariants) {
  auto l = parse_ok(kLayer);
  const PrimSpec* child = l->prim_at("/World/Child");
  ASSERT_NE(child, nullptr);
  EXPECT_EQ(child->type_name, "Mesh");
  EXPECT_EQ(child->path, "/World/Child");
  const PrimSpec* w = l->prim_at("/World");
  const VariantSetSpec* set = w->variant_set("shading");
  ASSERT_NE(set, nullptr);
  ASSERT_EQ(set->variants.size(), 2u);
  const PrimSpec* red = set->find("red");
  ASSERT_NE(red, nullptr);
  ASSERT_NE(red->property("c"), nullptr);
  EXPECT_EQ(red->property("c")->default_value.numbers, (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(red->meta("kind")->text.at(0), "subcomponent");
  EXPECT_EQ(red->path, "/World") << "a variant's opinions are about its owning prim";
}

TEST(UsdaParser, LaterSpecsOfOnePropertyInOneLayerWin) {
  // OpenUSD's lbs.usda declares points twice in one prim; the second declaration is the one it uses.
  auto l = parse_ok("#usda 1.0\ndef Mesh \"M\" {\n  point3f[] points = [(1, 1, 1)]\n  point3f[] points = [(2, 2, 2)]\n}\n");
  EXPECT_EQ(l->prim_at("/M")->property("points")->default_value.numbers, (std::vector<double>{2, 2, 2}));
}

// The parser converts the usual numbers itself (Clinger's fast path) and the rest with std::from_chars: every
// value must be the double from_chars gives, bit for bit (floats printed with 9 and 17 digits, fixed notation,
// and the edge cases of both paths).
TEST(UsdaParser, NumbersAreTheDoublesFromCharsGives) {
  std::vector<std::string> texts = {"0", "-0", "1", "-1", ".5", "5.", "1e5", "1E-5", "-2.5e+3", "123456789",
                                    "0.000123456789", "1e22", "1e-22", "1e23", "1e-23", "12345678901234567890",
                                    "0.1", "3.40282e+38", "1.17549435e-38", "4.9e-324", "00012", "0.000", "9007199254740993",
                                    "0.30000000000000004", "2.2250738585072014e-308"};
  std::uint32_t state = 12345u;  // a fixed linear congruential sequence of float bit patterns
  for (int i = 0; i < 3000; ++i) {
    state = state * 1664525u + 1013904223u;
    float x;
    std::memcpy(&x, &state, 4);
    if (!std::isfinite(x)) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, i % 3 == 0 ? "%.9g" : i % 3 == 1 ? "%.17g" : "%.6f", double(x));
    texts.push_back(buf);
  }
  std::string layer = "#usda 1.0\ndef \"A\" {\n  double[] a = [";
  for (const auto& t : texts) layer += t + ", ";
  layer += "]\n}\n";
  auto l = parse_ok(layer);
  const auto& got = l->prim_at("/A")->property("a")->default_value.numbers;
  ASSERT_EQ(got.size(), texts.size());
  for (std::size_t i = 0; i < texts.size(); ++i) {
    const std::string& t = texts[i];
    const bool negative = t[0] == '-';
    double expect = 0.0;
    std::from_chars(t.data() + negative, t.data() + t.size(), expect);
    if (negative) expect = -expect;
    EXPECT_EQ(std::memcmp(&got[i], &expect, sizeof(double)), 0) << t << ": " << got[i] << " vs " << expect;
  }
  // Beyond double: infinity and zero, as strtod gives them.
  auto big = parse_ok("#usda 1.0\ndef \"A\" {\n  double[] a = [1e400, -1e400, 1e-400]\n}\n");
  const auto& b = big->prim_at("/A")->property("a")->default_value.numbers;
  ASSERT_EQ(b.size(), 3u);
  EXPECT_TRUE(std::isinf(b[0]) && b[0] > 0);
  EXPECT_TRUE(std::isinf(b[1]) && b[1] < 0);
  EXPECT_EQ(b[2], 0.0);
}

TEST(UsdaParser, ResolvesRelativePaths) {
  EXPECT_EQ(absolute_path("/A/B", "C"), "/A/B/C");
  EXPECT_EQ(absolute_path("/A/B", "../C"), "/A/C");
  EXPECT_EQ(absolute_path("/A/B", "../../C/D"), "/C/D");
  EXPECT_EQ(absolute_path("/A/B", ".prop"), "/A/B.prop");
  EXPECT_EQ(absolute_path("/A/B", "/X"), "/X");
  EXPECT_EQ(absolute_path("/A", "Shader.outputs:rgb"), "/A/Shader.outputs:rgb");
}

struct BadCase {
  const char* text;
  const char* position;  // file:line:column
  const char* message;   // part of the message
};

TEST(UsdaParser, MalformedTextGivesFileLineColumn) {
  const BadCase cases[] = {
      {"def Xform \"A\" {}\n", "bad.usda:1:1", "first line must be '#usda 1.0'"},
      {"#usda 1.0\ndef Xform \"A\" {\n    float x = \"s\"\n}\n", "bad.usda:3:15", "does not match its type"},
      {"#usda 1.0\ndef Xform \"A\" {\n    flaot x = 1\n}\n", "bad.usda:3:5", "unknown value type 'flaot'"},
      {"#usda 1.0\ndef Xform \"A\" {\n    float3 p = (1, 2)\n}\n", "bad.usda:3:16", "needs 3 numbers per element"},
      {"#usda 1.0\ndef Xform \"A\" {\n", "bad.usda:3:1", "expected '}' to close prim 'A'"},
      {"#usda 1.0\ndef \"A\" (\n    doc = \"never closed\n)\n{}\n", "bad.usda:3:11", "unterminated string"},
      {"#usda 1.0\ndef \"1abc\" {}\n", "bad.usda:2:1", "not a valid prim name"},
      {"#usda 1.0\ndef \"A\" {\n  int[] a = [1, \"x\"]\n}\n", "bad.usda:3:20", "mixes values of different kinds"},
      {"#usda 1.0\ndef \"A\" {\n  float2[] a = [(1, 2), (1, 2, 3)]\n}\n", "bad.usda:3:34", "mixes tuples of 2 and 3"},
      {"#usda 1.0\ndef \"A\" {\n  rel r = @x@\n}\n", "bad.usda:3:3", "must be paths"},
      {"#usda 1.0\ndef \"A\" (\n  references = 12\n) {}\n", "bad.usda:3:16", "expected a reference"},
      {"#usda 1.0\ndef \"A\" {\n  float a.spline = {}\n}\n", "bad.usda:3:3", "splines are not supported"},
      {"#usda 2.0\n", "bad.usda:1:7", "unsupported .usda version"},
  };
  for (const BadCase& c : cases) {
    auto l = parse_usda(c.text, "bad.usda");
    ASSERT_FALSE(l) << c.text;
    EXPECT_EQ(l.error().file, c.position) << c.text << "\n" << l.error().message;
    EXPECT_NE(l.error().message.find(c.message), std::string::npos) << l.error().message;
    EXPECT_EQ(l.error().kind, ErrorKind::Input);
  }
}

TEST(UsdaParser, DeepNestingAndTruncationAreErrorsNotCrashes) {
  std::string deep = "#usda 1.0\ndef \"A\" {\n  float x = " + std::string(5000, '(') + "1" + std::string(5000, ')') + "\n}\n";
  auto l = parse_usda(deep, "deep.usda");
  ASSERT_FALSE(l);
  EXPECT_NE(l.error().message.find("nested too deeply"), std::string::npos) << l.error().message;
  // Every prefix of a valid layer is either valid or an error; none crashes (the fuzz target goes further).
  const std::string text = kLayer;
  for (std::size_t n = 0; n < text.size(); n += 7) (void)parse_usda(text.substr(0, n), "prefix.usda");
}

}  // namespace
}  // namespace temporal::usd
