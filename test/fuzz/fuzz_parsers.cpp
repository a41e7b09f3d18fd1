// fuzz_parsers: a seeded mutation fuzzer over every parser of user files (scenario YAML, effects
// files, dataset YAML and CSV, model sidecar YAML, IR look-up table, validation reference tables and
// mismatch reasons, switching route files). Each parser gets mutants of the shipped files (its corpus)
// for an equal share of the time budget; a mutant may be refused (any C++ exception is an answer)
// but must not end its process by a signal, hang, or take memory beyond a bound:
//   * every mutant runs in a forked worker (batches of them), under RLIMIT_AS = kMemoryBound above
//     the worker's own size at the start; an allocation beyond it ends the worker with status 97;
//   * alarm(kSecondsPerInput) per mutant: a hang ends the worker with SIGALRM;
//   * a worker that ends by any signal (or status 97) is a failure: the mutant is written beside the
//     test's output (fuzz_failure_<parser>_<n>.txt) and named, and the test fails.
// A scenario that parses (with few robots) is also built and stepped, since degenerate geometry
// used to fail only in ODE.
//
// Mutants are a function of (seed, parser, index) alone, so a failure is reproduced by its numbers:
//   SBOT_FUZZ_SEED (default 1), SBOT_FUZZ_SECONDS (default 60; the whole budget, shared by parsers),
//   SBOT_FUZZ_ONLY=<parser> to fuzz one parser.
// In the test suite as ctest `fuzz_parsers` (./sbot.sh test); by hand:
//   build/ws/devel/lib/swarmbot3d/fuzz_parsers   (or ctest -R fuzz_parsers --output-on-failure)
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <new>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <dirent.h>

#include "calibration/dataset.h"
#include "course_run.h"
#include "mismatch_reasons.h"
#include "reference_tables.h"
#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/scenario.h"
#include "sbot_sim/core/scenario_world.h"
#include "sbot_sim/core/sensors/proximity.h"
#include "sbot_sim/core/world.h"

namespace {

constexpr unsigned kSecondsPerInput = 10;            ///< a mutant answered later than this is a hang
constexpr rlim_t kMemoryBound = 1024ull << 20;       ///< [bytes] address space a worker may add
constexpr int kOutOfMemoryStatus = 97;               ///< a worker's exit status for an allocation beyond it
constexpr int kBatch = 400;                          ///< mutants per worker process

/// The repository root: SWARMBOT3D_SOURCE_DIR is the workspace's package folder, whose items link
/// into the root (sbot.sh workspace()); the corpus also lies in the other packages beside them.
const std::string kSource = [] {
  char root[PATH_MAX];
  const std::string package_xml = std::string(SWARMBOT3D_SOURCE_DIR) + "/package.xml";
  if (!realpath(package_xml.c_str(), root)) return std::string(SWARMBOT3D_SOURCE_DIR);
  const std::string r = root;
  return r.substr(0, r.rfind('/'));
}();

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeAll(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

/// The files in `dir` whose names end with `suffix` (and not with `exclude`, when given).
std::vector<std::string> filesIn(const std::string& dir, const std::string& suffix, const std::string& exclude = "") {
  std::vector<std::string> out;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string n = e->d_name;
      const auto ends = [&](const std::string& s) { return !s.empty() && n.size() >= s.size() && n.compare(n.size() - s.size(), s.size(), s) == 0; };
      if (ends(suffix) && !ends(exclude)) out.push_back(dir + "/" + n);
    }
    closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Values that parsers have got wrong before, or that sit on a boundary.
const std::vector<std::string>& interesting() {
  static const std::vector<std::string> v = {
      "~", "null", "", "0", "-0", "1", "-1", "1e308", "-1e308", "1e-20", "5e-324", "1e20", ".nan", ".inf", "-.inf",
      "nan", "inf", "4294967296", "9223372036854775808", "-9223372036854775809", "0x10", "1e400", "true", "[]",
      "{}", "[1, 2]", "[1e-20, 0.6, 0.1]", "&a [*a]", "*a", "'", "\"", "\\", "- ", ": ", "? ", "#", "%YAML 1.2",
      "/dev/zero", "/proc/self/fd/0", std::string(300, 'a'), std::string(10000, 'b'), ",", ",,", "\n", "\t", "\r\n",
      "\xff\xfe", std::string("\0", 1)};
  return v;
}

/// One mutant of `text` (a corpus file; `others` for splicing), from `rng`.
std::string mutate(std::string text, const std::vector<std::string>& others, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng() % n); };
  const int rounds = 1 + static_cast<int>(rng() % 4);
  for (int r = 0; r < rounds; ++r) {
    const std::size_t at = pick(text.size() + 1);
    switch (rng() % 8) {
      case 0:  // a number replaced by an interesting value (reaches the range checks)
      case 1: {
        std::vector<std::size_t> starts;
        for (std::size_t i = 0; i < text.size(); ++i)
          if ((std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '-') &&
              (i == 0 || !std::isalnum(static_cast<unsigned char>(text[i - 1]))))
            starts.push_back(i);
        if (starts.empty()) break;
        const std::size_t s = starts[pick(starts.size())];
        std::size_t e = s + 1;
        while (e < text.size() && (std::isalnum(static_cast<unsigned char>(text[e])) || text[e] == '.' || text[e] == '-' || text[e] == '+')) ++e;
        text.replace(s, e - s, interesting()[pick(interesting().size())]);
        break;
      }
      case 2:  // an interesting token inserted
        text.insert(at, interesting()[pick(interesting().size())]);
        break;
      case 3:  // a byte flipped
        if (!text.empty()) text[pick(text.size())] ^= static_cast<char>(1u << (rng() % 8));
        break;
      case 4: {  // a range deleted
        const std::size_t n = std::min(text.size() - std::min(at, text.size()), pick(64) + 1);
        text.erase(std::min(at, text.size()), n);
        break;
      }
      case 5: {  // a range repeated
        if (text.empty()) break;
        const std::size_t s = pick(text.size()), n = std::min(text.size() - s, pick(200) + 1);
        text.insert(at, text.substr(s, n));
        break;
      }
      case 6: {  // lines of another corpus file spliced in
        const std::string& o = others[pick(others.size())];
        if (o.empty()) break;
        const std::size_t s = pick(o.size()), n = std::min(o.size() - s, pick(400) + 1);
        text.insert(at, o.substr(s, n));
        break;
      }
      case 7: {  // a line's value replaced: "key: VALUE" -> "key: <interesting>"
        const std::size_t colon = text.find(": ", at);
        if (colon == std::string::npos) break;
        const std::size_t end = text.find('\n', colon);
        text.replace(colon + 2, (end == std::string::npos ? text.size() : end) - colon - 2,
                     interesting()[pick(interesting().size())]);
        break;
      }
    }
  }
  return text;
}

struct Parser {
  std::string name;
  std::vector<std::string> corpus;                    ///< files' contents
  std::function<void(const std::string& mutant)> run;  ///< throws to refuse
};

/// A scratch folder for the files a parser reads by path.
std::string scratch() {
  static const std::string dir = [] {
    char tmpl[] = "/tmp/sbot_fuzz_XXXXXX";
    return std::string(mkdtemp(tmpl));
  }();
  return dir;
}

std::vector<Parser> parsers() {
  std::vector<Parser> out;
  auto contents = [](const std::vector<std::string>& files) {
    std::vector<std::string> c;
    for (const auto& f : files) c.push_back(readAll(f));
    return c;
  };
  std::vector<std::string> scenarios = filesIn(kSource + "/config/scenarios", ".yaml", ".route.yaml");
  for (const auto& f : filesIn(kSource + "/sbot_sim/test/node/fixtures", ".yaml", ".effects.yaml")) scenarios.push_back(f);
  out.push_back({"scenario", contents(scenarios), [](const std::string& m) {
                   const std::string path = scratch() + "/scenario.yaml";
                   writeAll(path, m);
                   const sbot::Scenario s = sbot::loadScenario(path);
                   // Built and stepped too (degenerate geometry failed only in ODE), when small.
                   if (s.robots.size() > 4 || s.world.terrain.type == sbot::TerrainConfig::Type::Rough ||
                       s.world.terrain.boxes.size() > 300)
                     return;
                   auto w = sbot::buildScenarioWorld(s);
                   for (sbot::Robot* r : w->robots()) r->setSpeed(70, 60);
                   w->stepN(static_cast<int>(0.2 / s.world.step));
                 }});
  out.push_back({"effects", contents(filesIn(kSource + "/sbot_sim/test/node/fixtures", ".effects.yaml")),
                 [](const std::string& m) { sbot::parseEffectsConfig(m, "fuzz.effects.yaml"); }});
  // Datasets: a mutant dataset.yaml beside the example's run files, or one mutant run file.
  const std::string ds_dir = scratch() + "/dataset";
  mkdir(ds_dir.c_str(), 0700);
  std::vector<std::string> ds_yamls, run_files;
  for (const char* d : {"example", "seed_ground_response", "seed_ir_response", "seed_traction"}) {
    ds_yamls.push_back(kSource + "/datasets/" + d + "/dataset.yaml");
    for (const auto& f : filesIn(kSource + "/datasets/" + d, ".csv")) {
      run_files.push_back(f);
      writeAll(ds_dir + f.substr(f.rfind('/')), readAll(f));
    }
  }
  out.push_back({"dataset_yaml", contents(ds_yamls), [ds_dir](const std::string& m) {
                   writeAll(ds_dir + "/dataset.yaml", m);
                   sbot::calib::loadDataset(ds_dir);
                 }});
  out.push_back({"dataset_csv", contents(run_files), [](const std::string& m) {
                   sbot::calib::Run run;
                   sbot::calib::parseRunCsv(m, "fuzz.csv", run);
                 }});
  out.push_back({"sidecar", contents(filesIn(kSource + "/sbot_description/urdf", ".sbot.yaml")), [](const std::string& m) {
                   const std::string path = scratch() + "/medium.sbot.yaml";
                   writeAll(path, m);
                   sbot::loadRobotDescription(kSource + "/sbot_description/urdf/medium.urdf", path);
                 }});
  out.push_back({"ir_table", contents({kSource + "/sbot_description/config/ir_lut.yaml"}), [](const std::string& m) {
                   const std::string path = scratch() + "/ir_lut.yaml";
                   writeAll(path, m);
                   sbot::sensors::IrLookupTable::load(path);
                 }});
  out.push_back({"reference_tables", contents({kSource + "/" + sbot::validation::kReferenceTablesFile}),
                 [](const std::string& m) {
                   // sbot_validate's sections, paragraphs and levels (as test_reference_tables.cpp).
                   static const sbot::validation::ReferenceVocabulary vocabulary{
                       {"facts", "4.1pair", "4.4", "compat", "fig4.4"},
                       {"backward_step_statics"},
                       {"fast", "simple", "basic", "medium", "detailed"},
                       {{"4.1pair", "hardware"}}};
                   const std::string path = scratch() + "/reference_tables.yaml";
                   writeAll(path, m);
                   sbot::validation::ReferenceTables::load(path, vocabulary);
                 }});
  out.push_back({"mismatch_reasons", contents({kSource + "/" + sbot::validation::kMismatchReasonsFile}),
                 [](const std::string& m) {
                   const std::string path = scratch() + "/mismatch_reasons.yaml";
                   writeAll(path, m);
                   sbot::validation::MismatchReasons::load(path);
                 }});
  out.push_back({"route", contents(filesIn(kSource + "/config/scenarios", ".route.yaml")), [](const std::string& m) {
                   const std::string path = scratch() + "/course.route.yaml";
                   writeAll(path, m);
                   switching::loadRoute(path);
                 }});
  return out;
}

std::uint64_t envNumber(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 10) : fallback;
}

std::string mutantOf(const Parser& p, std::uint64_t seed, std::uint64_t index, std::size_t parser_index) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull ^ (parser_index * 1000003ull + index * 7919ull));
  const std::string& base = p.corpus[rng() % p.corpus.size()];
  return mutate(base, p.corpus, rng);
}

[[noreturn]] void outOfMemory() { std::_Exit(kOutOfMemoryStatus); }

/// [bytes] The address space this process has now.
rlim_t addressSpace() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmSize:", 0) == 0) return static_cast<rlim_t>(std::strtoull(line.c_str() + 7, nullptr, 10)) * 1024;
  return 0;
}

TEST(FuzzParsers, NoMutantOfAShippedFileEndsByASignalHangsOrExceedsTheMemoryBound) {
  const std::uint64_t seed = envNumber("SBOT_FUZZ_SEED", 1);
  const double budget = static_cast<double>(envNumber("SBOT_FUZZ_SECONDS", 60));
  const char* only = std::getenv("SBOT_FUZZ_ONLY");
  std::vector<Parser> all = parsers();
  if (only && *only) all.erase(std::remove_if(all.begin(), all.end(), [&](const Parser& p) { return p.name != only; }), all.end());
  ASSERT_FALSE(all.empty()) << "no parser called '" << (only ? only : "") << "'";
  // The worker writes the index of the mutant it is on here, so that a dead one can be named.
  auto* current = static_cast<std::uint64_t*>(
      mmap(nullptr, 2 * sizeof(std::uint64_t), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(current, MAP_FAILED);
  std::uint64_t total = 0;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> failures;
  for (std::size_t pi = 0; pi < all.size(); ++pi) {
    const Parser& p = all[pi];
    ASSERT_FALSE(p.corpus.empty()) << p.name << ": no corpus file found under " << kSource;
    const double share = budget / static_cast<double>(all.size());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(share);
    std::uint64_t next = 0, refused = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      current[0] = next;
      current[1] = 0;  // refusals in this batch
      std::fflush(stdout);
      std::fflush(stderr);
      const pid_t pid = fork();
      ASSERT_GE(pid, 0);
      if (pid == 0) {
        // Quiet: parsers' refusals are expected by the thousand.
        if (FILE* null = std::freopen("/dev/null", "w", stderr)) (void)null;
        rlimit limit{addressSpace() + kMemoryBound, addressSpace() + kMemoryBound};
        setrlimit(RLIMIT_AS, &limit);
        std::set_new_handler(outOfMemory);
        for (int b = 0; b < kBatch && std::chrono::steady_clock::now() < deadline; ++b) {
          const std::uint64_t i = current[0];
          const std::string m = mutantOf(p, seed, i, pi);
          alarm(kSecondsPerInput);
          try {
            p.run(m);
          } catch (const std::bad_alloc&) {
            outOfMemory();
          } catch (const std::exception&) {
            ++current[1];
          }
          alarm(0);
          current[0] = i + 1;
        }
        std::_Exit(0);
      }
      int status = 0;
      waitpid(pid, &status, 0);
      refused += current[1];
      const bool killed = WIFSIGNALED(status);
      const bool memory = WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemoryStatus;
      if (killed || memory || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const std::uint64_t i = current[0];
        const std::string file = testing::TempDir() + "fuzz_failure_" + p.name + "_" + std::to_string(i) + ".txt";
        writeAll(file, mutantOf(p, seed, i, pi));
        std::string why = killed ? (WTERMSIG(status) == SIGALRM ? "hung (no answer within " + std::to_string(kSecondsPerInput) + " s)"
                                                               : std::string("killed by signal ") + std::to_string(WTERMSIG(status)) +
                                                                     " (" + strsignal(WTERMSIG(status)) + ")")
                            : memory ? "took more than " + std::to_string(kMemoryBound >> 20) + " MiB"
                                     : "exited with status " + std::to_string(WEXITSTATUS(status));
        failures.push_back(p.name + " mutant " + std::to_string(i) + " (SBOT_FUZZ_SEED=" + std::to_string(seed) + "): " +
                           why + "; the input: " + file);
        current[0] = i + 1;  // go on after it
      }
      next = current[0];
    }
    std::printf("fuzz_parsers: %-17s %6llu mutants, %6llu refused\n", p.name.c_str(), static_cast<unsigned long long>(next),
                static_cast<unsigned long long>(refused));
    total += next;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("fuzz_parsers: %llu mutants of %zu parsers in %.1f s (seed %llu), %zu failures\n",
              static_cast<unsigned long long>(total), all.size(), wall, static_cast<unsigned long long>(seed), failures.size());
  for (const std::string& f : failures) ADD_FAILURE() << f;
  munmap(current, 2 * sizeof(std::uint64_t));
}

}  // namespace
