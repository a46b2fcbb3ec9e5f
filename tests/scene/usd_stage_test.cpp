// USD composition (libtemporal/src/scene/usd_stage.cpp) on small layers written to a scratch folder: layer
// stacks, references and payloads (defaultPrim, internal, path translation of relationship targets), variant
// selections from the referencing layer and nested variant sets, inherits, the LIVRPS strength order, layer
// offsets, and the composition errors and warnings.
#include "test_support.h"

#include "usd_stage.h"

#include <gtest/gtest.h>

#include <fstream>

namespace temporal::usd {
namespace {

namespace fs = std::filesystem;

class UsdStage : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir(std::string("usd_stage_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()); }
  std::string write(const std::string& name, const std::string& body) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << "#usda 1.0\n" << body;
    return p.string();
  }
  std::unique_ptr<Stage> open(const std::string& path) {
    auto s = Stage::open(path);
    EXPECT_TRUE(s) << (s ? "" : s.error().file + ": " + s.error().message);
    return s ? std::move(*s) : nullptr;
  }
  fs::path dir_;
};

// The value of a float attribute (default), or NaN.
double value(const Prim* p, const char* name) {
  if (!p) return std::nan("");
  const PropertySpec* a = p->attribute(name);
  return a && a->has_default && a->default_value.numbers.size() == 1 ? a->default_value.numbers[0] : std::nan("");
}

TEST_F(UsdStage, SubLayersComposeStrongestFirst) {
  write("strong.usda", "def Xform \"P\" {\n float a = 2\n float b = 2\n}\n");
  write("weak.usda", "def \"P\" {\n float b = 3\n float c = 3\n def \"Child\" {}\n}\n");
  auto s = open(write("root.usda", "(\n subLayers = [@strong.usda@, @weak.usda@]\n)\nover \"P\" {\n float a = 1\n}\n"));
  ASSERT_TRUE(s);
  const Prim* p = s->prim_at("/P");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type_name, "Xform");
  EXPECT_TRUE(p->defined()) << "a def in a weaker layer defines the prim";
  EXPECT_EQ(value(p, "a"), 1.0);
  EXPECT_EQ(value(p, "b"), 2.0);
  EXPECT_EQ(value(p, "c"), 3.0);
  EXPECT_NE(s->prim_at("/P/Child"), nullptr);
  EXPECT_EQ(s->layer_count(), 3u);
}

TEST_F(UsdStage, ReferencesMapTargetsIntoTheReferencingNamespace) {
  write("model.usda", R"((
 defaultPrim = "Model"
)
def Xform "Model" {
 def Mesh "Geo" {
  float x = 1
  rel material:binding = </Model/Looks/M>
  color3f inputs:c.connect = </Model/Looks/M/Tex.outputs:rgb>
 }
 def Scope "Looks" {
  def Material "M" {}
 }
}
)");
  auto s = open(write("root.usda", R"(def "Inst" (
 references = @model.usda@
) {
 over "Geo" {
  float x = 5
 }
}
def "Second" (
 references = @./model.usda@</Model>
) {}
)"));
  ASSERT_TRUE(s);
  const Prim* geo = s->prim_at("/Inst/Geo");
  ASSERT_NE(geo, nullptr);
  EXPECT_EQ(geo->type_name, "Mesh");
  EXPECT_EQ(value(geo, "x"), 5.0) << "the referencing layer's opinion is stronger";
  EXPECT_EQ(geo->targets("material:binding"), std::vector<std::string>{"/Inst/Looks/M"});
  EXPECT_EQ(geo->connections("inputs:c"), std::vector<std::string>{"/Inst/Looks/M/Tex.outputs:rgb"});
  const Prim* geo2 = s->prim_at("/Second/Geo");
  ASSERT_NE(geo2, nullptr);
  EXPECT_EQ(value(geo2, "x"), 1.0);
  EXPECT_EQ(geo2->targets("material:binding"), std::vector<std::string>{"/Second/Looks/M"});
  EXPECT_EQ(s->prim_at("/Inst")->type_name, "Xform");
}

TEST_F(UsdStage, InternalReferencesAndPayloads) {
  write("payload.usda", "(\n defaultPrim = \"Heavy\"\n)\ndef Mesh \"Heavy\" {\n float p = 9\n}\n");
  auto s = open(write("root.usda", R"(class "Proto" {
 float a = 7
}
def "Copy" (
 references = </Proto>
) {}
def "Loaded" (
 payload = @payload.usda@
) {}
)"));
  ASSERT_TRUE(s);
  EXPECT_EQ(value(s->prim_at("/Copy"), "a"), 7.0);
  EXPECT_TRUE(s->prim_at("/Copy")->defined()) << "the referencing def wins over the class specifier";
  EXPECT_TRUE(s->prim_at("/Proto")->abstract);
  EXPECT_EQ(value(s->prim_at("/Loaded"), "p"), 9.0);
  EXPECT_EQ(s->prim_at("/Loaded")->type_name, "Mesh");
}

TEST_F(UsdStage, VariantSelectionsComeFromTheStrongestOpinionAndNest) {
  write("model.usda", R"((
 defaultPrim = "Model"
)
def "Model" (
 variants = {
  string look = "red"
 }
 prepend variantSets = "look"
) {
 variantSet "look" = {
  "red" (
   variants = {
    string shade = "dark"
   }
   prepend variantSets = "shade"
  ) {
   float v = 1
   variantSet "shade" = {
    "dark" { float d = 0.1 }
    "light" { float d = 0.9 }
   }
  }
  "blue" {
   float v = 2
   def "OnlyInBlue" {}
  }
 }
}
)");
  auto s = open(write("root.usda", R"(def "A" (
 references = @model.usda@
 variants = {
  string look = "blue"
 }
) {}
def "B" (
 references = @model.usda@
) {}
def "C" (
 references = @model.usda@
 variants = {
  string shade = "light"
 }
) {}
)"));
  ASSERT_TRUE(s);
  EXPECT_EQ(value(s->prim_at("/A"), "v"), 2.0) << "the referencing layer's selection wins";
  EXPECT_NE(s->prim_at("/A/OnlyInBlue"), nullptr) << "a variant's children are composed";
  EXPECT_EQ(value(s->prim_at("/B"), "v"), 1.0) << "the referenced layer's own selection";
  EXPECT_EQ(s->prim_at("/B/OnlyInBlue"), nullptr);
  EXPECT_DOUBLE_EQ(value(s->prim_at("/B"), "d"), 0.1) << "a variant set declared inside a variant";
  EXPECT_DOUBLE_EQ(value(s->prim_at("/C"), "d"), 0.9);
}

TEST_F(UsdStage, StrengthOrderIsLocalInheritsVariantsReferences) {
  write("ref.usda", "(\n defaultPrim = \"R\"\n)\ndef \"R\" {\n float w = 4\n float r = 4\n float v = 4\n float i = 4\n}\n");
  auto s = open(write("root.usda", R"(class "_c" {
 float w = 2
 float i = 2
 float v = 2
}
def "E" (
 inherits = </_c>
 references = @ref.usda@
 variants = {
  string set = "one"
 }
 prepend variantSets = "set"
) {
 float w = 1
 variantSet "set" = {
  "one" {
   float w = 3
   float v = 3
   float r = 3
  }
 }
}
)"));
  ASSERT_TRUE(s);
  const Prim* e = s->prim_at("/E");
  EXPECT_EQ(value(e, "w"), 1.0) << "local";
  EXPECT_EQ(value(e, "i"), 2.0) << "inherits over variants and references";
  EXPECT_EQ(value(e, "v"), 2.0) << "inherits over variants";
  EXPECT_EQ(value(e, "r"), 3.0) << "variants over references";
  ASSERT_EQ(e->sites.size(), 4u);
}

TEST_F(UsdStage, LayerOffsetsMapTimes) {
  write("anim.usda", "(\n defaultPrim = \"A\"\n)\ndef \"A\" {\n float t.timeSamples = {\n  0: 1,\n  1: 2,\n }\n}\n");
  write("sub.usda", "def \"S\" {\n float t.timeSamples = {\n  0: 1,\n }\n}\n");
  auto s = open(write("root.usda", "(\n subLayers = [@sub.usda@ (offset = 10; scale = 2)]\n)\ndef \"R\" (\n references = @anim.usda@ (offset = 5)\n) {}\n"));
  ASSERT_TRUE(s);
  const Site* site = nullptr;
  const Prim* r = s->prim_at("/R");
  ASSERT_NE(r, nullptr);
  ASSERT_NE(r->attribute("t", &site), nullptr);
  EXPECT_DOUBLE_EQ(site->offset.offset, 5.0);
  EXPECT_DOUBLE_EQ(site->offset.offset + site->offset.scale * 1.0, 6.0) << "layer time 1 is stage time 6";
  ASSERT_NE(s->prim_at("/S")->attribute("t", &site), nullptr);
  EXPECT_DOUBLE_EQ(site->offset.offset, 10.0);
  EXPECT_DOUBLE_EQ(site->offset.scale, 2.0);
}

// Issue 26: an arc cycle (a prim that references itself through other layers) is an Input error naming the
// arc's position; a reference to a missing prim stays a warning, as in OpenUSD.
TEST_F(UsdStage, MissingPrimsAreWarningsCyclesAndMissingLayersAreErrors) {
  write("a.usda", "(\n defaultPrim = \"A\"\n)\ndef \"A\" (\n references = @b.usda@\n) {}\n");
  write("b.usda", "(\n defaultPrim = \"B\"\n)\ndef \"B\" (\n references = @a.usda@\n) {\n float b = 1\n}\n");
  write("c.usda", "(\n defaultPrim = \"C\"\n)\ndef \"C\" {\n float b = 1\n}\n");
  auto cyclic = Stage::open(write("cyclic.usda", "def \"X\" (\n references = @a.usda@\n) {}\n"));
  ASSERT_FALSE(cyclic);
  EXPECT_NE(cyclic.error().message.find("cycle"), std::string::npos) << cyclic.error().message;
  EXPECT_NE(cyclic.error().file.find(".usda:"), std::string::npos) << cyclic.error().file;
  auto s = open(write("root.usda", "def \"X\" (\n references = @c.usda@\n) {}\ndef \"Y\" (\n references = @c.usda@</Nope>\n) {}\n"));
  ASSERT_TRUE(s);
  EXPECT_EQ(value(s->prim_at("/X"), "b"), 1.0);
  bool missing = false;
  for (const auto& w : s->warnings()) missing = missing || w.find("</Nope>") != std::string::npos;
  EXPECT_TRUE(missing);

  auto bad = Stage::open(write("bad.usda", "def \"Z\" (\n references = @gone.usda@\n) {}\n"));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().file, (dir_ / "bad.usda").string() + ":3:15");
  EXPECT_NE(bad.error().message.find("gone.usda"), std::string::npos) << bad.error().message;

  write("nodefault.usda", "def \"N\" {}\n");
  auto nodef = Stage::open(write("nodef.usda", "def \"Z\" (\n references = @nodefault.usda@\n) {}\n"));
  ASSERT_FALSE(nodef);
  EXPECT_NE(nodef.error().message.find("no defaultPrim"), std::string::npos) << nodef.error().message;

  write("broken.usda", "def \"Q\" {\n float = 1\n}\n");
  auto broken = Stage::open(write("uses_broken.usda", "def \"Z\" (\n references = @broken.usda@</Q>\n) {}\n"));
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().file, (dir_ / "broken.usda").string() + ":3:8") << "the parse error of the referenced layer";

  std::ofstream(dir_ / "crate.usdc") << "PXR-USDC" << std::string(80, '\0');
  auto crate = Stage::open(write("uses_crate.usda", "def \"Z\" (\n references = @crate.usdc@</Q>\n) {}\n"));
  ASSERT_FALSE(crate);
  EXPECT_NE(crate.error().message.find("usdcat -o"), std::string::npos) << crate.error().message;
}

}  // namespace
}  // namespace temporal::usd
