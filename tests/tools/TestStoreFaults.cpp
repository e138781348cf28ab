// Fault injection end to end through the `strata` program: a map survives SIGKILL at any moment,
// a full disk, read-only permissions, a second writer, damaged tile files and a catalog from a
// newer strata, and every failure names what is wrong.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "CliTestUtil.hpp"
#include "Format4Map.hpp"
#include "MapDiff.hpp"
#include "StoreFaultUtil.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/store/MapStore.hpp"

namespace store_faults_tests {
namespace {

namespace fs = std::filesystem;
using strata::core::VoxelMap;
using strata::store::MapStore;
using strata::tools::test::Child;
using strata::tools::test::FaultSequence;
using strata::tools::test::IntegrateArgs;
using strata::tools::test::Join;
using strata::tools::test::JsonIn;
using strata::tools::test::KillAt;
using strata::tools::test::KillAttempts;
using strata::tools::test::kSequenceScans;
using strata::tools::test::kTileM;
using strata::tools::test::kVoxelM;
using strata::tools::test::LoadLatest;
using strata::tools::test::MakeSequence;
using strata::tools::test::MapFiles;
using strata::tools::test::OpenForReading;
using strata::tools::test::Outcome;
using strata::tools::test::ReadText;
using strata::tools::test::Result;
using strata::tools::test::SameMap;
using strata::tools::test::Seed;
using strata::tools::test::SequenceSpec;
using strata::tools::test::SessionCount;
using strata::tools::test::Spawn;
using strata::tools::test::Strata;
using strata::tools::test::Temp;
using strata::tools::test::Wait;
using Clock = std::chrono::steady_clock;

constexpr int kExitBadFormat = 6;   // README, "Exit codes"
constexpr double kOneTileM = 64.0;  // with --origin 32,32,0 the whole room is in one tile
// Reader processes and the sessions the writer commits while they read.
constexpr int kReaders = 3;
constexpr int kWriterSessions = 6;
constexpr double kCommitMarginS = 0.05;  // the commit window starts a little earlier than timed
constexpr double kHangGuardS = 5.0;  // a refused writer returns at once; this only catches hangs
constexpr rlim_t kSmallFileLimit = 64 << 10;   // below one tile file (>100 kB) and a new catalog
constexpr rlim_t kLargeFileLimit = 512 << 10;  // a new catalog fits, one 64 m tile (~1 MB) not

// The maps a run without faults produces, built one session ahead of the map under test (which
// has n or n + 1 sessions after an attempt at session n + 1), and how long each session took.
class Reference {
public:
    struct Timing {
        double total_s = 0.0;   // fork to exit of `strata integrate`
        double commit_s = 0.0;  // the commit alone, as the program reports it
    };

    Reference(fs::path map, fs::path seq) : map_(std::move(map)), seq_(std::move(seq)) {
        fs::create_directories(map_.parent_path());
        maps_.emplace(0, VoxelMap::Create(kVoxelM));
    }

    // Integrates sessions until the reference has `sessions`; false (with the output) on failure.
    ::testing::AssertionResult BuildTo(int sessions) {
        while (built_ < sessions) {
            const fs::path log = map_.parent_path() / "integrate.log";
            const Outcome out = Wait(Spawn(IntegrateArgs(map_, seq_, built_ + 1), log));
            const std::string text = ReadText(log);
            std::smatch commit;
            if (out.code != 0 ||
                !std::regex_search(text, commit, std::regex("commit ([0-9.e+-]+) s"))) {
                return ::testing::AssertionFailure()
                       << "reference session " << built_ + 1 << " failed:\n"
                       << text;
            }
            ++built_;
            timings_[built_] = {out.seconds, std::stod(commit[1].str())};
            maps_.emplace(built_, LoadLatest(map_));
            // Only the last two are ever asked for: the map under test has n or n + 1 sessions.
            maps_.erase(maps_.begin(), maps_.lower_bound(built_ - 1));
        }
        return ::testing::AssertionSuccess();
    }

    [[nodiscard]] const VoxelMap& MapAfter(int sessions) const { return maps_.at(sessions); }
    [[nodiscard]] const Timing& TimingOf(int session) const { return timings_.at(session); }

private:
    fs::path map_;
    fs::path seq_;
    int built_ = 0;
    std::map<int, VoxelMap> maps_;
    std::map<int, Timing> timings_;
};

// Every file the map directory may hold besides tiles/ (SQLite's WAL files come and go).
bool IsMapFile(const std::string& name) {
    return name == "tiles" || name == "writer.lock" || name.rfind("catalog.sqlite", 0) == 0;
}

// A map with `sessions` sessions of FaultSequence, and the sequence.
struct Fixture {
    fs::path seq;
    fs::path map;
};

Fixture MakeMap(const std::string& name, int sessions, double tile_m = kTileM) {
    Fixture f{MakeSequence(Temp(name + "_seq"), FaultSequence()), Temp(name) / "map"};
    for (int s = 1; s <= sessions; ++s) {
        const Result r = Strata(Join(IntegrateArgs(f.map, f.seq, s, tile_m)));
        EXPECT_EQ(r.code, 0) << r.out;
    }
    return f;
}

// The key property of the store: whenever a writer dies, the map on disk is exactly the map of
// the sessions committed before it, or of those and the one it was writing; never anything else,
// and never a damaged file.
TEST(StoreFaults, KilledIntegrationsLeaveTheMapOfTheCommittedSessions) {
    const unsigned seed = Seed();
    std::mt19937 rng(seed);
    const fs::path seq = MakeSequence(Temp("faults_crash_seq"), FaultSequence());
    const fs::path root = Temp("faults_crash");
    fs::create_directories(root);
    const fs::path map = root / "map";
    const fs::path log = Temp("faults_crash.log");
    Reference reference(Temp("faults_crash_ref") / "map", seq);

    std::ostringstream history;  // every attempt, printed with any failure
    history << "seed " << seed << " (set STRATA_FAULT_SEED to rerun it)\n";
    int sessions = 0, killed = 0, completed = 0;
    const int attempts = KillAttempts();
    for (int attempt = 0; attempt < attempts; ++attempt) {
        const int next = sessions + 1;
        ASSERT_TRUE(reference.BuildTo(next)) << history.str();
        // Kill anywhere (3 in 8), inside the commit at the end of the run (4 in 8), or never.
        // Completions are kept rare: every session makes the next ones and `check` slower.
        const Reference::Timing& t = reference.TimingOf(next);
        const int where = std::uniform_int_distribution<int>(0, 7)(rng);
        const double lo = where < 3 ? 0.0 : std::max(0.0, t.total_s - t.commit_s - kCommitMarginS);
        const double hi = where < 7 ? t.total_s : 3.0 * t.total_s;
        const double delay_s = std::uniform_real_distribution<double>(lo, hi)(rng);

        const Child child = Spawn(IntegrateArgs(map, seq, next), log);
        const Outcome out =
            KillAt(child, child.start + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(delay_s)));
        history << "attempt " << attempt << ": session " << next << ", kill at " << delay_s
                << " s of ~" << t.total_s << " s (commit ~" << t.commit_s
                << " s): " << (out.killed ? "killed" : "exited " + std::to_string(out.code))
                << " after " << out.seconds << " s";
        SCOPED_TRACE(history.str());
        if (!out.killed) {
            ASSERT_EQ(out.code, 0) << ReadText(log);
        }

        if (!MapStore::IsMap(map)) {
            // Killed while creating the map: no map, at most a directory the next attempt's
            // integrate completes (the next test covers creation in detail).
            history << " -> no map\n";
            ASSERT_EQ(sessions, 0);
            ASSERT_TRUE(out.killed);
            continue;
        }
        const Result check = Strata("check " + map.string() + " --json");
        ASSERT_EQ(check.code, 0) << check.out;
        const nlohmann::json report = JsonIn(check.out);
        ASSERT_TRUE(report.contains("problems")) << check.out;
        ASSERT_TRUE(report["problems"].empty()) << check.out;

        const int n = static_cast<int>(SessionCount(map));
        history << " -> " << n << " sessions, " << report["unreferenced"].size()
                << " unreferenced files\n";
        ASSERT_TRUE(n == sessions || n == sessions + 1) << n << " sessions";
        if (!out.killed) {
            ASSERT_EQ(n, sessions + 1);
        }
        ASSERT_TRUE(SameMap(LoadLatest(map), reference.MapAfter(n)));
        killed += out.killed && n == sessions;
        completed += n == sessions + 1;
        sessions = n;
    }
    SCOPED_TRACE(history.str());
    std::cout << history.str();
    // How many kills landed mid-session depends on the machine's load: reported, not asserted
    // beyond one of each, without which the loop proved nothing.
    std::printf("%d attempts: %d killed mid-session, %d completed\n", attempts, killed, completed);
    EXPECT_GE(killed, 1);
    EXPECT_GE(completed, 1);
    ASSERT_TRUE(MapStore::IsMap(map));

    // gc removes exactly what the kills left behind; the map is unchanged and clean after it.
    const nlohmann::json before_gc = JsonIn(Strata("check " + map.string() + " --json").out);
    const Result gc = Strata("gc " + map.string());
    ASSERT_EQ(gc.code, 0) << gc.out;
    for (const auto& file : before_gc["unreferenced"]) {
        EXPECT_NE(gc.out.find("removed " + file.get<std::string>()), std::string::npos) << gc.out;
    }
    const Result after_gc = Strata("check " + map.string() + " --json");
    ASSERT_EQ(after_gc.code, 0) << after_gc.out;
    EXPECT_TRUE(JsonIn(after_gc.out)["unreferenced"].empty()) << after_gc.out;
    for (const auto& e : fs::directory_iterator(map)) {
        EXPECT_TRUE(IsMapFile(e.path().filename().string())) << e.path();
    }
    EXPECT_TRUE(SameMap(LoadLatest(map), reference.MapAfter(sessions)));

    // The next writer finds the lock free and the map whole.
    ASSERT_TRUE(reference.BuildTo(sessions + 1));
    const Result next = Strata(Join(IntegrateArgs(map, seq, sessions + 1)));
    ASSERT_EQ(next.code, 0) << next.out;
    ASSERT_EQ(SessionCount(map), static_cast<size_t>(sessions + 1));
    EXPECT_TRUE(SameMap(LoadLatest(map), reference.MapAfter(sessions + 1)));
}

// A writer killed while it creates the map leaves nothing: no map, and nothing beside it.
// A first integrate killed while it creates the map leaves no map, a complete map, or a directory
// the next integrate turns into a map; never hidden files beside it.
// Reader processes run `strata info --json` (and one of them `strata export`) in a loop while a
// writer process commits sessions:
// every answer must be exactly the map after some whole number of sessions (never a mix), and no
// reader may fail because of the writer.
TEST(StoreFaults, ReaderProcessesSeeWholeCommitsWhileAWriterCommits) {
    const fs::path seq = MakeSequence(Temp("faults_readers_seq"), FaultSequence());
    // What `info` says after k sessions, from a map built without readers.
    const fs::path reference = Temp("faults_readers_ref") / "map";
    std::map<size_t, std::pair<uint64_t, uint64_t>> expected;  // sessions -> occupied, free
    for (int s = 1; s <= kWriterSessions; ++s) {
        ASSERT_EQ(Strata(Join(IntegrateArgs(reference, seq, s))).code, 0);
        const nlohmann::json j = JsonIn(Strata("info " + reference.string() + " --json").out);
        expected[static_cast<size_t>(s)] = {j["occupied_voxels"], j["free_voxels"]};
    }
    const fs::path root = Temp("faults_readers");
    fs::create_directories(root);
    const fs::path map = root / "map";
    ASSERT_EQ(Strata(Join(IntegrateArgs(map, seq, 1))).code, 0);

    // Each reader: one line per answer (the JSON on one line, or FAIL and the exit code) until
    // the stop file appears, then DONE. The guard writes the stop file however the test ends (an
    // ASSERT returns early), and a reader also stops after kReaderLimitS, so none loops forever.
    const fs::path stop = root / "stop";
    struct StopReaders {
        fs::path file;
        ~StopReaders() { std::ofstream(file) << "stop"; }
    } stop_readers{stop};
    constexpr int kReaderLimitS = 600;
    for (int r = 0; r < kReaders; ++r) {
        const std::string out = (root / ("reader_" + std::to_string(r) + ".txt")).string();
        const fs::path script = root / ("reader_" + std::to_string(r) + ".sh");
        std::ofstream(script) << "end=$(($(date +%s) + " << kReaderLimitS << "))\n"
                              << "while [ ! -e '" << stop.string()
                              << "' ] && [ $(date +%s) -lt $end ]; do\n"
                              << "  '" << STRATA_BINARY << "' info '" << map.string()
                              << "' --json > '" << out << ".one' 2>&1\n"
                              << "  rc=$?\n"
                              << "  if [ $rc -eq 0 ]; then tr -d '\\n' < '" << out << ".one' >> '"
                              << out << "'; echo >> '" << out << "'\n"
                              << "  else echo FAIL $rc >> '" << out << "'; cat '" << out
                              << ".one' >> '" << out << "'; fi\n"
                              << (r == 0 ? "  '" + std::string(STRATA_BINARY) + "' export '" +
                                               map.string() + "' --out '" + out +
                                               ".vdb' > /dev/null 2>&1 || echo FAIL export >> '" +
                                               out + "'\n"
                                         : std::string())
                              << "done\necho DONE >> '" << out << "'\n";
        ASSERT_EQ(std::system(("sh '" + script.string() + "' > /dev/null 2>&1 &").c_str()), 0);
    }
    for (int s = 2; s <= kWriterSessions; ++s) {
        const Result r = Strata(Join(IntegrateArgs(map, seq, s)));
        ASSERT_EQ(r.code, 0) << r.out;
    }
    std::ofstream(stop) << "stop";

    std::set<size_t> seen;
    size_t answers = 0;
    for (int r = 0; r < kReaders; ++r) {
        const fs::path out = root / ("reader_" + std::to_string(r) + ".txt");
        const auto deadline = Clock::now() + std::chrono::seconds(60);
        while (ReadText(out).find("DONE") == std::string::npos && Clock::now() < deadline) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        std::istringstream lines(ReadText(out));
        std::string line;
        while (std::getline(lines, line)) {
            if (line == "DONE" || line.empty()) continue;
            ASSERT_NE(line.rfind("FAIL", 0), 0u) << "reader " << r << ": " << ReadText(out);
            const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
            ASSERT_FALSE(j.is_discarded()) << "reader " << r << ": " << line;
            const size_t sessions = j["sessions"].size();
            ASSERT_TRUE(expected.count(sessions)) << line;
            EXPECT_EQ(j["occupied_voxels"].get<uint64_t>(), expected[sessions].first) << line;
            EXPECT_EQ(j["free_voxels"].get<uint64_t>(), expected[sessions].second) << line;
            seen.insert(sessions);
            ++answers;
        }
    }
    // How many commits the readers saw depends on the machine's speed: reported, not asserted.
    std::printf("%zu answers from %d readers, %zu distinct commits seen\n", answers, kReaders,
                seen.size());
    EXPECT_GE(answers, static_cast<size_t>(kReaders)) << "every reader answered at least once";
}

TEST(StoreFaults, KilledMapCreationLeavesNothingHiddenAndRecovers) {
    using std::chrono::microseconds;
    // Creation is over in milliseconds on a quiet machine; the steps grow by a tenth of the
    // delay, so a loaded machine still finds it (at most about 80 kills up to 5 s).
    constexpr microseconds kMaxDelay{5000000};
    constexpr microseconds kCoarseStep{2000};
    // Creation lasts a few milliseconds and process start-up jitters by more: kill many times
    // in the last kFineWindow before the first kill that found a map.
    constexpr microseconds kFineWindow{20000};
    constexpr int kFineKills = 30;
    const fs::path seq = MakeSequence(Temp("faults_create_seq"), FaultSequence());
    const fs::path log = Temp("faults_create.log");
    std::set<std::string> leftovers;
    // Kills a first integrate `delay` after its start; true when the map was complete by then.
    const auto kill_at = [&](microseconds delay) {
        const std::string when = "kill at " + std::to_string(delay.count()) + " us";
        const fs::path root = Temp("faults_create");
        fs::create_directories(root);
        const Child child = Spawn(IntegrateArgs(root / "map", seq, 1), log);
        const Outcome out = KillAt(child, child.start + delay);
        const bool is_map = MapStore::IsMap(root / "map");
        for (const auto& e : fs::directory_iterator(root)) {
            const std::string name = e.path().filename().string();
            if (name != "map") leftovers.insert(name + " (" + when + ")");
        }
        if (!is_map && fs::exists(root / "map")) {
            // Killed before it wrote anything, the directory is just empty: nothing to explain.
            if (!fs::is_empty(root / "map")) {
                const Result info = Strata("info " + (root / "map").string());
                EXPECT_NE(info.out.find("creation was interrupted"), std::string::npos)
                    << when << ": " << info.out;
            }
            const Result again = Strata(Join(IntegrateArgs(root / "map", seq, 1)));
            EXPECT_EQ(again.code, 0) << when << ": " << again.out;
            EXPECT_TRUE(MapStore::IsMap(root / "map")) << when;
        } else if (is_map) {
            const Result check = Strata("check " + (root / "map").string());
            EXPECT_EQ(check.code, 0) << when << ": " << check.out;
        }
        return is_map || !out.killed;
    };
    microseconds created{-1};
    for (microseconds delay{0}; delay <= kMaxDelay && created.count() < 0;
         delay += std::max(kCoarseStep, delay / 10)) {
        if (kill_at(delay)) created = delay;
    }
    ASSERT_GE(created.count(), 0) << "no kill within " << kMaxDelay.count() << " us came after "
                                  << "the creation";
    for (int k = 0; k < kFineKills; ++k) {
        (void)kill_at(std::max(microseconds{0}, created - kFineWindow * k / kFineKills));
    }
    EXPECT_TRUE(leftovers.empty()) << [&] {
        std::string all;
        for (const std::string& l : leftovers) all += l + "\n";
        return all;
    }();
}

// A full disk (here: a file-size limit) fails the command with a message naming the file, and
// leaves the map as it was: same catalog view, same files, nothing to clean up.
TEST(StoreFaults, FullDiskFailsAndLeavesTheMapAsItWas) {
    const Fixture f = MakeMap("faults_disk", 1);
    const auto files_before = MapFiles(f.map);
    const VoxelMap map_before = LoadLatest(f.map);
    const fs::path log = Temp("faults_disk.log");

    const Outcome out = Wait(Spawn(IntegrateArgs(f.map, f.seq, 2), log, kSmallFileLimit));
    const std::string text = ReadText(log);
    EXPECT_FALSE(out.killed);
    EXPECT_NE(out.code, 0) << text;
    EXPECT_NE(text.find((f.map / "tiles").string()), std::string::npos) << text;  // the tile file
    EXPECT_NE(text.find(".vdb"), std::string::npos) << text;

    EXPECT_EQ(SessionCount(f.map), 1u);
    EXPECT_TRUE(SameMap(LoadLatest(f.map), map_before));
    EXPECT_EQ(MapFiles(f.map), files_before);
    const Result check = Strata("check " + f.map.string() + " --json");
    EXPECT_EQ(check.code, 0) << check.out;
    EXPECT_TRUE(JsonIn(check.out)["unreferenced"].empty()) << check.out;

    // A first integrate that fails leaves no map and nothing beside it, whether the catalog
    // (small limit: MapStore::Create fails) or the first tile (large limit: the whole room in
    // one 64 m tile, thanks to the origin) is what does not fit.
    for (const auto& [limit, file] : {std::pair<rlim_t, std::string>{kSmallFileLimit, "catalog"},
                                      std::pair<rlim_t, std::string>{kLargeFileLimit, ".vdb"}}) {
        const fs::path root = Temp("faults_disk_new");
        fs::create_directories(root);
        std::vector<std::string> args = IntegrateArgs(root / "map", f.seq, 1, kOneTileM);
        args.insert(args.end(), {"--origin", "32,32,0"});
        const Outcome first = Wait(Spawn(args, log, limit));
        const std::string message = ReadText(log);
        EXPECT_NE(first.code, 0) << "limit " << limit << ": " << message;
        EXPECT_NE(message.find(root.string()), std::string::npos) << message;
        EXPECT_NE(message.find(file), std::string::npos) << message;
        EXPECT_TRUE(fs::is_empty(root)) << "limit " << limit << ": " << message;
    }
}

// `strata ARGS` with calls failing on every file whose path holds `on` (tests/tools/EioShim.cpp):
// by default fsync/fdatasync with EIO; `calls` "write" fails the writes, `error` "ENOSPC" says
// the disk is full.
Result StrataWithEio(const std::string& on, const std::string& args,
                     const std::string& calls = "sync", const std::string& error = "EIO") {
    const std::string cmd = "STRATA_EIO_ON='" + on + "' STRATA_EIO_CALLS=" + calls +
                            " STRATA_EIO_ERRNO=" + error + " LD_PRELOAD='" + STRATA_EIO_SHIM +
                            "' '" + STRATA_BINARY + "' " + args + " 2>&1";
    Result r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    char buf[4096];
    while (pipe && std::fgets(buf, sizeof buf, pipe)) r.out += buf;
    const int status = pipe ? ::pclose(pipe) : -1;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// A disk that reports an I/O error when the data is flushed: on a new tile file, and on the
// catalog. Either way the command fails naming what it could not write, and the map stays the
// map of the sessions before, checks clean, and takes the next session.
TEST(StoreFaults, IoErrorsOnFlushFailTheCommitAndLeaveTheMap) {
    const Fixture f = MakeMap("faults_eio", 1);
    const auto files_before = MapFiles(f.map);
    const VoxelMap map_before = LoadLatest(f.map);
    for (const auto& [on, named] :
         {std::pair<std::string, std::string>{"/tiles/", "Input/output error"},
          std::pair<std::string, std::string>{"catalog.sqlite",
                                              "catalog.sqlite: disk I/O error"}}) {
        const Result r = StrataWithEio(on, Join(IntegrateArgs(f.map, f.seq, 2)));
        EXPECT_NE(r.code, 0) << on << ": " << r.out;
        EXPECT_NE(r.out.find(named), std::string::npos) << on << ": " << r.out;
        EXPECT_NE(r.out.find(f.map.string()), std::string::npos) << on << ": " << r.out;
        EXPECT_EQ(SessionCount(f.map), 1u) << on;
        EXPECT_TRUE(SameMap(LoadLatest(f.map), map_before)) << on;
        EXPECT_EQ(MapFiles(f.map), files_before) << on;
        const Result check = Strata("check " + f.map.string() + " --json");
        EXPECT_EQ(check.code, 0) << check.out;
    }
    const Result next = Strata(Join(IntegrateArgs(f.map, f.seq, 2)));
    EXPECT_EQ(next.code, 0) << next.out;
    EXPECT_EQ(SessionCount(f.map), 2u);
}

// The write itself fails, with EIO (a bad disk) or ENOSPC (a full one; a real full disk, not the
// file-size limit of FullDiskFailsAndLeavesTheMapAsItWas): on the new tile files, then on the
// catalog (its write-ahead log for ENOSPC). The commit fails with the file and the cause, the
// map stays the map of the sessions before, byte for byte, `strata check` is clean, and the
// next commit works.
TEST(StoreFaults, WriteErrorsFailTheCommitAndLeaveTheMap) {
    const Fixture f = MakeMap("faults_write", 1);
    const auto files_before = MapFiles(f.map);
    const VoxelMap map_before = LoadLatest(f.map);
    struct Case {
        std::string on, error, named;
    };
    const std::vector<Case> cases{
        {"/tiles/", "EIO", "Input/output error"},
        {"/tiles/", "ENOSPC", "No space left on device"},
        {"catalog.sqlite", "EIO", "catalog.sqlite: disk I/O error"},
        // SQLite says "full" when the write-ahead log cannot grow; the same errno on its shared
        // memory file (-shm) is an I/O error to it.
        {"catalog.sqlite-wal", "ENOSPC", "catalog.sqlite: database or disk is full"}};
    for (const Case& c : cases) {
        const std::string what = c.error + " on " + c.on;
        const Result r =
            StrataWithEio(c.on, Join(IntegrateArgs(f.map, f.seq, 2)), "write", c.error);
        EXPECT_NE(r.code, 0) << what << ": " << r.out;
        EXPECT_NE(r.out.find(c.named), std::string::npos) << what << ": " << r.out;
        const std::string file =
            c.on == "/tiles/" ? (f.map / "tiles").string() : (f.map / "catalog.sqlite").string();
        EXPECT_NE(r.out.find(file), std::string::npos) << what << ": " << r.out;
        EXPECT_EQ(SessionCount(f.map), 1u) << what;
        EXPECT_TRUE(SameMap(LoadLatest(f.map), map_before)) << what;
        EXPECT_EQ(MapFiles(f.map), files_before) << what;
        const Result check = Strata("check " + f.map.string() + " --json");
        EXPECT_EQ(check.code, 0) << what << ": " << check.out;
        EXPECT_TRUE(JsonIn(check.out)["unreferenced"].empty()) << what << ": " << check.out;
    }
    const Result next = Strata(Join(IntegrateArgs(f.map, f.seq, 2)));
    EXPECT_EQ(next.code, 0) << next.out;
    EXPECT_EQ(SessionCount(f.map), 2u);
}

// A map without write permission bits is read-only for strata even for root: writes are refused
// with a message, reads work, nothing changes.
TEST(StoreFaults, ReadOnlyMapRefusesWritersAndServesReaders) {
    const Fixture f = MakeMap("faults_readonly", 1);
    const auto files_before = MapFiles(f.map);
    // Restores the write bits however the test ends, so later runs can remove the directory.
    struct RestoreWriteBits {
        fs::path dir;
        ~RestoreWriteBits() { (void)std::system(("chmod -R u+w " + dir.string()).c_str()); }
    } restore{f.map};
    ASSERT_EQ(std::system(("chmod -R a-w " + f.map.string()).c_str()), 0);

    const Result integrate = Strata(Join(IntegrateArgs(f.map, f.seq, 2)));
    EXPECT_NE(integrate.code, 0);
    EXPECT_NE(integrate.out.find("read-only"), std::string::npos) << integrate.out;
    const Result gc = Strata("gc " + f.map.string());
    EXPECT_NE(gc.code, 0);
    EXPECT_NE(gc.out.find("read-only"), std::string::npos) << gc.out;

    const Result info = Strata("info " + f.map.string() + " --json");
    ASSERT_EQ(info.code, 0) << info.out;
    EXPECT_EQ(JsonIn(info.out)["sessions"].size(), 1u) << info.out;
    EXPECT_EQ(Strata("check " + f.map.string()).code, 0);
    EXPECT_EQ(MapFiles(f.map), files_before);
    EXPECT_EQ(SessionCount(f.map), 1u);
}

// While one process writes, another writer is refused at once, naming the holder; readers go on.
TEST(StoreFaults, SecondWriterIsRefusedAtOnce) {
    const Fixture f = MakeMap("faults_lock", 1);
    const std::string pid = "pid " + std::to_string(::getpid());
    {
        const MapStore writer = MapStore::Open(f.map, MapStore::Access::kWrite);
        for (const std::string& command :
             {Join(IntegrateArgs(f.map, f.seq, 2)), "gc " + f.map.string()}) {
            const auto start = Clock::now();
            const Result r = Strata(command);
            const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            EXPECT_NE(r.code, 0) << command;
            EXPECT_NE(r.out.find("another strata process (" + pid + ")"), std::string::npos)
                << r.out;
            EXPECT_LT(seconds, kHangGuardS) << command;
        }
        EXPECT_EQ(Strata("info " + f.map.string()).code, 0);
        EXPECT_EQ(SessionCount(f.map), 1u);
    }
    // The lock goes with its holder.
    const Result next = Strata(Join(IntegrateArgs(f.map, f.seq, 2)));
    EXPECT_EQ(next.code, 0) << next.out;
    EXPECT_EQ(SessionCount(f.map), 2u);
}

// A flipped byte and a truncated file: check lists both, reads that need them fail naming one,
// every other tile still reads.
TEST(StoreFaults, DamagedTileFilesAreNamed) {
    const Fixture f = MakeMap("faults_damage", 2);
    const MapStore store = OpenForReading(f.map);
    const std::vector<strata::store::TileVersion> tiles = store.Latest().tiles;
    ASSERT_GE(tiles.size(), 3u);
    const strata::store::TileVersion& flipped = tiles.front();
    const strata::store::TileVersion& truncated = tiles.back();
    {
        std::fstream file(f.map / flipped.file, std::ios::in | std::ios::out | std::ios::binary);
        const auto middle = static_cast<std::streamoff>(flipped.bytes / 2);
        char byte = 0;
        file.seekg(middle);
        file.read(&byte, 1);
        byte = static_cast<char>(~byte);
        file.seekp(middle);
        file.write(&byte, 1);
        ASSERT_TRUE(file.good());
    }
    constexpr uintmax_t kTruncatedBytes = 8;
    fs::resize_file(f.map / truncated.file, kTruncatedBytes);

    const Result check = Strata("check " + f.map.string());
    EXPECT_EQ(check.code, kExitBadFormat);
    EXPECT_NE(check.out.find(flipped.file), std::string::npos) << check.out;
    EXPECT_NE(check.out.find(truncated.file), std::string::npos) << check.out;
    const Result check_json = Strata("check " + f.map.string() + " --json");
    EXPECT_EQ(check_json.code, kExitBadFormat);
    const nlohmann::json report = JsonIn(check_json.out);
    std::set<std::string> bad;
    for (const auto& p : report["problems"]) bad.insert(p["file"].get<std::string>());
    EXPECT_EQ(bad, (std::set<std::string>{flipped.file, truncated.file})) << check_json.out;

    const fs::path exported = Temp("faults_damage.vdb");
    for (const std::string& command :
         {"info " + f.map.string(), "export " + f.map.string() + " --out " + exported.string()}) {
        const Result r = Strata(command);
        EXPECT_NE(r.code, 0) << command;
        EXPECT_TRUE(r.out.find(flipped.file) != std::string::npos ||
                    r.out.find(truncated.file) != std::string::npos)
            << command << ": " << r.out;
    }
    EXPECT_FALSE(fs::exists(exported));

    for (const auto& tile : tiles) {
        if (tile.file == flipped.file || tile.file == truncated.file) continue;
        EXPECT_NO_THROW((void)store.ReadFused(tile)) << tile.file;
    }
    const auto error_of = [&](const strata::store::TileVersion& tile) -> std::string {
        try {
            (void)store.ReadFused(tile);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "no error";
    };
    EXPECT_NE(error_of(flipped).find("checksum"), std::string::npos) << error_of(flipped);
    EXPECT_NE(error_of(truncated).find("truncated"), std::string::npos) << error_of(truncated);
}

// A catalog a newer strata wrote is refused, not misread; a directory that is no map says so.
TEST(StoreFaults, NewerFormatsAndNonMapsAreRefused) {
    const Fixture f = MakeMap("faults_newer", 1);
    const fs::path copy = Temp("faults_newer_copy");
    fs::copy(f.map, copy, fs::copy_options::recursive);
    {
        sqlite3* db = nullptr;
        ASSERT_EQ(
            sqlite3_open_v2((copy / "catalog.sqlite").c_str(), &db, SQLITE_OPEN_READWRITE, nullptr),
            SQLITE_OK);
        const int rc = sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr);
        sqlite3_close(db);
        ASSERT_EQ(rc, SQLITE_OK);
    }
    const auto files_before = MapFiles(copy);
    for (const std::string& command :
         {"info " + copy.string(), "check " + copy.string(), Join(IntegrateArgs(copy, f.seq, 2))}) {
        const Result r = Strata(command);
        EXPECT_NE(r.code, 0) << command;
        EXPECT_NE(r.out.find("newer"), std::string::npos) << command << ": " << r.out;
    }
    EXPECT_EQ(MapFiles(copy), files_before);

    const fs::path empty = Temp("faults_emptydir");
    fs::create_directories(empty);
    const Result r = Strata("info " + empty.string());
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.out.find("not a strata map"), std::string::npos) << r.out;
}

}  // namespace

namespace {

// The integration rule is recorded when the map is created: a later `integrate` with a flag that
// contradicts it fails naming the flag, the map's value and the given one, and writes nothing; the
// same flag with the map's value, or no flag, is fine.
TEST(StoreFaults, IntegrateRefusesFlagsThatContradictTheMapsRule) {
    const Fixture f = MakeMap("faults_rule", 0);
    std::vector<std::string> first = IntegrateArgs(f.map, f.seq, 1);
    first.insert(first.end(), {"--max-range", "30"});
    ASSERT_EQ(Strata(Join(first)).code, 0);
    const auto files_before = MapFiles(f.map);
    for (const auto& [flag, named] : std::vector<std::pair<std::string, std::string>>{
             {"--max-range 40", "--max-range 40: "},
             {"--min-range 1", "--min-range 1: "},
             {"--points-only", "--points-only: "},
             {"--no-point-means", "--no-point-means: "}}) {
        const Result r = Strata(Join(IntegrateArgs(f.map, f.seq, 2)) + " " + flag);
        EXPECT_EQ(r.code, 2) << flag << ": " << r.out;  // a usage error
        EXPECT_NE(r.out.find(named), std::string::npos) << r.out;
        EXPECT_NE(r.out.find(f.map.string()), std::string::npos) << r.out;
    }
    EXPECT_NE(Strata(Join(IntegrateArgs(f.map, f.seq, 2)) + " --max-range 40")
                  .out.find("built with --max-range 30"),
              std::string::npos);
    EXPECT_EQ(MapFiles(f.map), files_before);
    EXPECT_EQ(SessionCount(f.map), 1u);
    const Result same = Strata(Join(IntegrateArgs(f.map, f.seq, 2)) + " --max-range 30");
    EXPECT_EQ(same.code, 0) << same.out;
    const Result none = Strata(Join(IntegrateArgs(f.map, f.seq, 3)));
    EXPECT_EQ(none.code, 0) << none.out;
    EXPECT_NE(none.out.find("range [0, 30] m"), std::string::npos) << none.out;
    EXPECT_EQ(OpenForReading(f.map).settings().integration.max_range_m, 30.0);
}

// History you can drop: `gc --keep-last` keeps the newest snapshots, `info --json` reports the
// bytes by kind before and after, `--as-of` an older session is refused saying why, and the
// session's layers still serve `diff`.
TEST(StoreFaults, GcKeepLastDropsOldHistoryAndInfoShowsTheBytes) {
    const Fixture f = MakeMap("faults_history", 4);
    const nlohmann::json before = JsonIn(Strata("info " + f.map.string() + " --json").out);
    ASSERT_TRUE(before.contains("bytes")) << before.dump();
    const nlohmann::json& b = before["bytes"];
    EXPECT_GT(b["fused_current"].get<uint64_t>(), 0u);
    EXPECT_GT(b["fused_older"].get<uint64_t>(), 0u);
    EXPECT_GT(b["layers"].get<uint64_t>(), 0u);
    EXPECT_EQ(b["products"].get<uint64_t>(), 0u);
    EXPECT_EQ(before["history_start_commit"].get<int64_t>(), 1);
    const Result bad = Strata("gc " + f.map.string() + " --keep-last 2 --keep-since 2024-01-01");
    EXPECT_EQ(bad.code, 2) << bad.out;
    EXPECT_NE(bad.out.find("exactly one"), std::string::npos) << bad.out;
    const Result gc = Strata("gc " + f.map.string() + " --keep-last 1");
    ASSERT_EQ(gc.code, 0) << gc.out;
    EXPECT_NE(gc.out.find("history kept from commit 5"), std::string::npos) << gc.out;
    const nlohmann::json after = JsonIn(Strata("info " + f.map.string() + " --json").out);
    EXPECT_EQ(after["bytes"]["fused_older"].get<uint64_t>(), 0u);
    EXPECT_EQ(after["bytes"]["layers"], b["layers"]);
    EXPECT_EQ(after["occupied_voxels"], before["occupied_voxels"]);
    EXPECT_LT(after["disk_bytes"].get<uint64_t>(), before["disk_bytes"].get<uint64_t>());
    const Result as_of = Strata("info " + f.map.string() + " --as-of 1");
    EXPECT_EQ(as_of.code, 5) << as_of.out;  // not found: no longer kept
    EXPECT_NE(as_of.out.find("no longer kept"), std::string::npos) << as_of.out;
    const Result diff = Strata("diff " + f.map.string() + " --from 1 --to 4 --json");
    EXPECT_EQ(diff.code, 0) << diff.out;
    EXPECT_EQ(Strata("check " + f.map.string()).code, 0);
}

// `strata upgrade` says what it did, and that a current map needs nothing.
TEST(StoreFaults, UpgradeSaysWhatItDid) {
    const Fixture f = MakeMap("faults_upgrade", 2);
    const Result current = Strata("upgrade " + f.map.string());
    EXPECT_EQ(current.code, 0) << current.out;
    const std::string version = std::to_string(MapStore::kFormatVersion);
    EXPECT_NE(current.out.find("format " + version + " already"), std::string::npos) << current.out;
    strata::test::RewriteAsFormat4(f.map);
    const Result info = Strata("info " + f.map.string());
    EXPECT_EQ(info.code, 6) << info.out;  // bad format: says how to upgrade
    EXPECT_NE(info.out.find("strata upgrade " + f.map.string()), std::string::npos) << info.out;
    const Result upgrade = Strata("upgrade " + f.map.string());
    EXPECT_EQ(upgrade.code, 0) << upgrade.out;
    EXPECT_NE(upgrade.out.find("format 4 -> " + version), std::string::npos) << upgrade.out;
    EXPECT_EQ(Strata("check " + f.map.string()).code, 0);
    EXPECT_EQ(SessionCount(f.map), 2u);
}

}  // namespace
}  // namespace store_faults_tests
