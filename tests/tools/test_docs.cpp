// Issue 11 item 11: a user's checkout carries its own conventions. The README once sent users to
// ../shared/spec/pipeline.md, which exists only on the development machines; now the
// conventions (strain, terms, losses, file formats) are docs/conventions.md, and nothing a user
// reads (README, docs, --help and messages in the sources) names the development folder's spec.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
}  // namespace

TEST(Docs, TheCheckoutCarriesItsOwnConventions) {
  const fs::path root = YARNHOM_SOURCE_DIR;
  const std::string readme = slurp(root / "README.md");
  ASSERT_FALSE(readme.empty());
  EXPECT_NE(readme.find("docs/conventions.md"), std::string::npos) << "the README must point to the conventions";

  const std::string conv = slurp(root / "docs" / "conventions.md");
  ASSERT_FALSE(conv.empty()) << "docs/conventions.md is missing";
  // What a user needs to read or write the files and understand the figures.
  for (const char* heading : {"## 2. Strain", "## 3. The energy terms", "## 4. Input files", "## 5. The dataset file",
                              "## 6. Networks, normalization and losses", "## 7. The model file", "## 8. The baked file",
                              "## 10. Other files", "## 11. How the program treats files"})
    EXPECT_NE(conv.find(heading), std::string::npos) << heading;

  // Nothing a user reads names the development machines' spec.
  std::vector<fs::path> files = {root / "README.md"};
  for (const char* dir : {"docs", "core", "numerics", "io", "material", "cpu", "cuda", "train", "bake", "yarn",
                              "produce", "sim", "accuracy", "pipeline", "tools", "scripts"}) {
    if (!fs::is_directory(root / dir)) continue;
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".md" || ext == ".cpp" || ext == ".hpp" || ext == ".cu" || ext == ".cuh" ||
                                  ext == ".py" || ext == ".sh"))
        files.push_back(e.path());
    }
  }
  EXPECT_GT(files.size(), 50u);
  for (const fs::path& f : files) {
    const std::string text = slurp(f);
    EXPECT_EQ(text.find("shared/spec"), std::string::npos) << f;
    EXPECT_EQ(text.find("spec/pipeline.md"), std::string::npos) << f;
  }
}
