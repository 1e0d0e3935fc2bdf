// Issue #17's broken-file corpus: every file of tests/data/corpus/ (made by its make_corpus.py:
// test files cut short, emptied, with huge indices, NaN, other encodings, random bytes) and every
// regression file the fuzzers left in tests/data/fuzz/<format>/ is read the way a program reads
// it (load_scene(), read_exr(), load_measured()), forgiving and strict. The contract: the call
// returns a scene or throws radiosity::Error (std::bad_alloc is allowed too); nothing else
// escapes. A hang shows as the test's ctest timeout. The command's side (`radiosity check` exits
// 0 or 1 on each file) is the cli.check_corpus test.
#include <algorithm>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kData = fs::path(RADIOSITY_TEST_DATA);

/// The corpus files in name order (the MTL libraries are read through their OBJ files, the
/// generator and notes not at all).
std::vector<fs::path> corpus_files() {
  std::vector<fs::path> files;
  auto add = [&](const fs::path& dir) {
    if (!fs::is_directory(dir)) return;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && ext != ".mtl" && ext != ".py" && ext != ".md") files.push_back(e.path());
    }
  };
  add(kData / "corpus");
  add(kData / "fuzz");
  std::sort(files.begin(), files.end());
  return files;
}

enum class Outcome { loaded, error, out_of_memory, foreign };

/// Reads `path` as its extension says; `what` gets the foreign exception's message.
Outcome read(const fs::path& path, bool strict, std::string& what) {
  try {
    const std::string ext = path.extension().string();
    if (ext == ".exr") {
      (void)radiosity::read_exr(path);
    } else if (ext == ".binary") {
      (void)radiosity::load_measured(path);
    } else {
      radiosity::LoadOptions options;
      options.strict = strict;
      (void)radiosity::load_scene(path, options);
    }
    return Outcome::loaded;
  } catch (const radiosity::Error&) {
    return Outcome::error;
  } catch (const std::bad_alloc&) {
    return Outcome::out_of_memory;
  } catch (const std::exception& e) {
    what = e.what();
    return Outcome::foreign;
  } catch (...) {
    what = "(not a std::exception)";
    return Outcome::foreign;
  }
}

}  // namespace

TEST_SUITE("io") {

TEST_CASE("Broken-file corpus: every reader returns a scene or throws radiosity::Error, nothing else") {
  const std::vector<fs::path> files = corpus_files();
  // The generator writes about 90 files; fewer means the corpus was not found or not made.
  REQUIRE(files.size() >= 80);
  int loaded = 0, errors = 0;
  for (const fs::path& file : files) {
    for (const bool strict : {false, true}) {
      CAPTURE(file.string());
      CAPTURE(strict);
      std::string what;
      const Outcome outcome = read(file, strict, what);
      INFO("foreign exception: " << what);
      CHECK(outcome != Outcome::foreign);
      CHECK(outcome != Outcome::out_of_memory);  // no file here is large enough to need it
      loaded += outcome == Outcome::loaded ? 1 : 0;
      errors += outcome == Outcome::error ? 1 : 0;
      // Files that cannot mean anything must be refused, not read as an empty scene.
      const std::string name = file.filename().string();
      if (name.rfind("empty.", 0) == 0 || name.rfind("noise.", 0) == 0) CHECK(outcome == Outcome::error);
    }
  }
  MESSAGE(files.size() << " corpus files, forgiving and strict: " << loaded << " reads loaded, " << errors
                       << " refused with radiosity::Error");
  // Most are refused; some (a file cut after its last face, a Latin-1 group name) still mean a scene.
  CHECK(errors > loaded);
  CHECK(loaded > 0);
}

}  // TEST_SUITE
