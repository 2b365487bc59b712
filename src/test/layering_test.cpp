// The core's folders are layers (layers.txt, lowest first): this test reads every header and
// source under include/palcas_core/ and lib/ and fails naming the file and line of any
// include of a folder that is not lower than the file's own (same folder is fine; folders
// on one line of layers.txt are one layer and may not include each other). It also fails
// on a file outside any folder, an include of an unknown folder, and a folder under
// include/palcas_core/, lib/ or test/ that layers.txt does not list.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

/// layers.txt: one layer per line, its folders separated by blanks; '#' starts a comment line.
/// Returns folder -> layer index (0 = lowest); an empty map if the file cannot be read.
std::map<std::string, int> readLayers(const fs::path& file, std::vector<std::string>& problems) {
  std::map<std::string, int> rank;
  std::ifstream in(file);
  if (!in) {
    problems.push_back(file.string() + ": cannot be read");
    return rank;
  }
  std::string line;
  int layer = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string folder;
    bool any = false;
    while (words >> folder) {
      if (!rank.emplace(folder, layer).second)
        problems.push_back(file.string() + ": folder '" + folder + "' is listed twice");
      any = true;
    }
    if (any) ++layer;
  }
  if (rank.empty()) problems.push_back(file.string() + ": lists no folder");
  return rank;
}

/// The folder (first path component) of `path` below `base`, or nothing if it is not below
/// `base` or lies directly in it.
std::optional<std::string> folderBelow(const fs::path& path, const fs::path& base) {
  const fs::path rel = path.lexically_normal().lexically_relative(base.lexically_normal());
  if (rel.empty() || *rel.begin() == "..") return std::nullopt;
  auto it = rel.begin();
  const std::string first = it->string();
  if (++it == rel.end()) return std::nullopt;  // a file directly in base
  return first;
}

bool isCode(const fs::path& p) {
  const auto ext = p.extension().string();
  return ext == ".h" || ext == ".hpp" || ext == ".cpp" || ext == ".cc";
}

/// Every violation of the layering in the core rooted at `root` (the package folder holding
/// layers.txt, include/palcas_core/, lib/ and test/), one line each.
std::vector<std::string> layeringViolations(const fs::path& root, int* files_read = nullptr) {
  std::vector<std::string> problems;
  const auto rank = readLayers(root / "layers.txt", problems);
  if (rank.empty()) return problems;
  const fs::path headers = root / "include" / "palcas_core";
  const fs::path sources = root / "lib";
  const fs::path tests = root / "test";

  // Every folder is a listed layer.
  for (const fs::path& base : {headers, sources, tests}) {
    if (!fs::is_directory(base)) {
      problems.push_back(base.string() + ": missing");
      continue;
    }
    for (const auto& entry : fs::directory_iterator(base))
      if (entry.is_directory() && !rank.count(entry.path().filename().string()))
        problems.push_back(entry.path().string() + ": folder not listed in layers.txt");
  }

  // The folder of an included file: palcas_core/<folder>/... or a quoted include that
  // resolves next to the including file.
  const std::regex include_line(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
  int read = 0;
  for (const fs::path& base : {headers, sources}) {
    if (!fs::is_directory(base)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(base)) {
      if (!entry.is_regular_file() || !isCode(entry.path())) continue;
      ++read;
      const std::string file = entry.path().string();
      const auto own = folderBelow(entry.path(), base);
      if (!own || !rank.count(*own)) {
        problems.push_back(file + ": not in a folder listed in layers.txt");
        continue;
      }
      std::ifstream in(entry.path());
      std::string line;
      int number = 0;
      while (std::getline(in, line)) {
        ++number;
        std::smatch m;
        if (!std::regex_search(line, m, include_line)) continue;
        const std::string target = m[2];
        std::optional<std::string> theirs;
        if (target.rfind("palcas_core/", 0) == 0) {
          theirs = folderBelow(root / "include" / target, headers);
          if (!theirs) {
            problems.push_back(file + ":" + std::to_string(number) +
                               ": includes a header outside any folder: " + line);
            continue;
          }
        } else if (m[1] == "\"" && fs::exists(entry.path().parent_path() / target)) {
          const fs::path resolved = entry.path().parent_path() / target;
          theirs = folderBelow(resolved, headers);
          if (!theirs) theirs = folderBelow(resolved, sources);
          if (!theirs) continue;  // not part of the core
        } else {
          continue;  // a system or third-party header
        }
        const auto their_rank = rank.find(*theirs);
        if (their_rank == rank.end()) {
          problems.push_back(file + ":" + std::to_string(number) +
                             ": includes folder '" + *theirs + "', not in layers.txt: " + line);
        } else if (*theirs != *own && their_rank->second >= rank.at(*own)) {
          problems.push_back(file + ":" + std::to_string(number) + ": folder '" + *own +
                             "' includes '" + *theirs + "', not a lower layer: " + line);
        }
      }
    }
  }
  if (files_read) *files_read = read;
  return problems;
}

/// A scratch core under the temporary directory, removed at the end of the test.
class ScratchCore {
 public:
  ScratchCore() : root_(fs::temp_directory_path() / ("palcas_layering_test_" +
                                                     std::to_string(::getpid()))) {
    fs::remove_all(root_);
    write("layers.txt", "# lowest first\ncommon\nfederation metrics\nrsu\n");
    for (const char* folder : {"common", "federation", "metrics", "rsu"}) {
      fs::create_directories(root_ / "include/palcas_core" / folder);
      fs::create_directories(root_ / "lib" / folder);
      fs::create_directories(root_ / "test" / folder);
    }
    write("include/palcas_core/common/a.h", "#pragma once\n#include <vector>\n");
    write("include/palcas_core/rsu/r.h", "#pragma once\n#include \"palcas_core/common/a.h\"\n");
    write("lib/rsu/r.cpp", "#include \"palcas_core/rsu/r.h\"\n#include \"private.h\"\n");
    write("lib/rsu/private.h", "#pragma once\n");
  }
  ~ScratchCore() { fs::remove_all(root_); }
  void write(const std::string& rel, const std::string& text) {
    fs::create_directories((root_ / rel).parent_path());
    std::ofstream(root_ / rel) << text;
  }
  const fs::path& root() const { return root_; }

 private:
  fs::path root_;
};

std::string joined(const std::vector<std::string>& lines) {
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  return all;
}

/// The one problem found in a scratch core once `file` holds `text` ("" if not exactly one).
std::string theOnlyProblemWith(const std::string& file, const std::string& text) {
  ScratchCore core;
  core.write(file, text);
  const auto problems = layeringViolations(core.root());
  EXPECT_EQ(problems.size(), 1u) << joined(problems);
  return problems.size() == 1 ? problems[0] : "";
}

}  // namespace

TEST(Layering, CoreFoldersIncludeOnlyLowerLayers) {
  int files_read = 0;
  const auto problems = layeringViolations(PALCAS_CORE_SOURCE_DIR, &files_read);
  EXPECT_GT(files_read, 50) << "the scan found almost no sources; is the path right?";
  for (const auto& p : problems) ADD_FAILURE() << "layering: " << p;
}

TEST(Layering, ScratchCoreThatKeepsTheOrderPasses) {
  ScratchCore core;
  int files_read = 0;
  EXPECT_EQ(joined(layeringViolations(core.root(), &files_read)), "");
  EXPECT_EQ(files_read, 4);
}

TEST(Layering, DetectsAnIncludeOfAHigherFolder) {
  const std::string p = theOnlyProblemWith("include/palcas_core/common/bad.h",
                                           "#pragma once\n  # include <palcas_core/rsu/r.h>\n");
  EXPECT_NE(p.find("common/bad.h:2: folder 'common' includes 'rsu'"), std::string::npos) << p;
}

TEST(Layering, DetectsAnIncludeWithinOneLayer) {
  const std::string p =
      theOnlyProblemWith("lib/metrics/m.cpp", "#include \"palcas_core/federation/f.h\"\n");
  EXPECT_NE(p.find("folder 'metrics' includes 'federation'"), std::string::npos) << p;
}

TEST(Layering, DetectsARelativeIncludeOfAHigherFolder) {
  const std::string p = theOnlyProblemWith("lib/common/c.cpp", "#include \"../rsu/private.h\"\n");
  EXPECT_NE(p.find("folder 'common' includes 'rsu'"), std::string::npos) << p;
}

TEST(Layering, DetectsFilesAndFoldersOutsideTheLayers) {
  ScratchCore core;
  core.write("include/palcas_core/loose.h", "#pragma once\n");
  core.write("lib/common/old.cpp", "#include \"palcas_core/action.h\"\n");
  core.write("lib/common/unknown.cpp", "#include \"palcas_core/extra/x.h\"\n");
  core.write("test/extra/x_test.cpp", "\n");
  const std::string all = joined(layeringViolations(core.root()));
  EXPECT_NE(all.find("loose.h: not in a folder"), std::string::npos) << all;
  EXPECT_NE(all.find("old.cpp:1: includes a header outside any folder"), std::string::npos) << all;
  EXPECT_NE(all.find("unknown.cpp:1: includes folder 'extra', not in layers.txt"),
            std::string::npos) << all;
  EXPECT_NE(all.find("test/extra: folder not listed"), std::string::npos) << all;
}
