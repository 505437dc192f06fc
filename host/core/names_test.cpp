// Every option's name table: each value named once, each name read back as its value, and the
// command line, JSON readers and the panel agreeing because they read the same table.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "app/named_option.h"
#include "core/error.h"
#include "core/names.h"
#include "io/json_fields.h"
#include "recover/reflectance_recovery.h"
#include "relight/light_edits.h"
#include "render/method.h"
#include "render/obscurance_renderer.h"
#include "render/scene_data/bvh_layout.h"

namespace obscura {
namespace {

// Names unique and non-empty, values unique, and each round-trips; `values` is every value of
// the enum (so a value added to the enum but not to its table fails here).
template <typename E, std::size_t N>
void expectTableCovers(const NameTable<E, N>& table, std::initializer_list<E> values) {
  std::set<std::string_view> names;
  for (const Named<E>& entry : table) {
    EXPECT_FALSE(entry.name.empty());
    EXPECT_TRUE(names.insert(entry.name).second) << "name twice: " << entry.name;
    EXPECT_EQ(valueNamed(table, entry.name), entry.value) << entry.name;
  }
  EXPECT_EQ(values.size(), N);
  for (E value : values) EXPECT_FALSE(nameOf(table, value).empty()) << "a value without a name";
  EXPECT_EQ(valueNamed(table, "no-such-name"), std::nullopt);
}

TEST(NameTables, EveryEnumValueHasOneNameThatReadsBackAsIt) {
  using namespace render;
  expectTableCovers(kMethodNames, {Method::Obscurance, Method::PathTrace});
  expectTableCovers(kRhoKindNames, {RhoKind::Sqrt, RhoKind::Exp, RhoKind::Ao});
  expectTableCovers(kShadowSamplingNames, {ShadowSampling::Selection, ShadowSampling::PerLight});
  expectTableCovers(kDirtyTestNames, {DirtyTest::Auto, DirtyTest::Bounds, DirtyTest::Probe});
  expectTableCovers(kAmbientModelNames, {AmbientModel::Reached, AmbientModel::Global, AmbientModel::Seen});
  expectTableCovers(kLightSamplingNames, {LightSampling::Spatial, LightSampling::Area});
  expectTableCovers(kLightTypeNames, {LightType::Area, LightType::Point, LightType::Spot, LightType::Directional,
                                      LightType::Background});
  expectTableCovers(kTraversalNames, {Traversal::Wide, Traversal::Binary, Traversal::BinaryWhileWhile});
  expectTableCovers(kObscuranceSamplingNames, {true, false});
  expectTableCovers(kVertexRaysNames, {true, false});
  expectTableCovers(recover::kIndirectModelNames, {recover::IndirectModel::Constant, recover::IndirectModel::Obscurance,
                                                   recover::IndirectModel::Gather});
  expectTableCovers(relight::kAddedLightTypeNames,
                    {relight::AddedLightType::Point, relight::AddedLightType::Spot, relight::AddedLightType::Quad});
  // Recovery's subset keeps the full table's words.
  for (const auto& entry : recover::kRecoveryAmbientNames)
    EXPECT_EQ(nameOf(kAmbientModelNames, entry.value), entry.name);
}

TEST(NameTables, TraversalRequestsAreAutoThenTheTable) {
  const std::vector<std::string> names = render::traversalRequestNames();
  ASSERT_EQ(names.size(), render::kTraversalNames.size() + 1);
  EXPECT_EQ(names.front(), "auto");
  EXPECT_EQ(render::parseTraversal("auto"), std::nullopt);
  for (std::size_t i = 1; i < names.size(); ++i) EXPECT_TRUE(render::parseTraversal(names[i]).has_value()) << names[i];
  try {
    render::parseTraversal("zigzag");
    FAIL() << "an unknown traversal was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("auto, wide, binary, binary-while-while"), std::string::npos) << e.what();
  }
}

TEST(NameTables, SentenceListsTheNamesInOrder) {
  EXPECT_EQ(namesSentence(render::kMethodNames), "obscurance or pathtrace");
  EXPECT_EQ(namesSentence(render::kRhoKindNames), "sqrt, exp or ao");
}

TEST(NamedOption, ParsesTheWordIntoTheEnumAndRefusesOthersWithTheNames) {
  CLI::App app;
  render::AmbientModel ambient = render::AmbientModel::Reached;
  app::addNamedOption(app, "--ambient", ambient, render::kAmbientModelNames, "I_a model");
  app.parse("--ambient seen", false);
  EXPECT_EQ(ambient, render::AmbientModel::Seen);

  CLI::App strict;
  render::AmbientModel untouched = render::AmbientModel::Reached;
  app::addNamedOption(strict, "--ambient", untouched, render::kAmbientModelNames, "I_a model");
  try {
    strict.parse("--ambient sky", false);
    FAIL() << "an unknown word was accepted";
  } catch (const CLI::ValidationError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("sky"), std::string::npos) << what;
    EXPECT_NE(what.find("reached"), std::string::npos) << what;
  }
  EXPECT_EQ(untouched, render::AmbientModel::Reached);
}

TEST(NamedJsonField, ReadsTheWordOrNamesTheFileEntryAndTheChoices) {
  const std::string file = "view.json";
  const io::JsonEntry at{file, 3};
  EXPECT_EQ(io::jsonNamed(nlohmann::json{{"rho", "exp"}}, "rho", render::kRhoKindNames, at), render::RhoKind::Exp);
  try {
    io::jsonNamed(nlohmann::json{{"rho", "cubic"}}, "rho", render::kRhoKindNames, at);
    FAIL() << "an unknown word was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("view.json"), std::string::npos) << what;
    EXPECT_NE(what.find("'rho' is sqrt, exp or ao"), std::string::npos) << what;
  }
}

} // namespace
} // namespace obscura
