// The kill suite for the commands that rewrite a map's history: `strata upgrade` (format 4 -> 5)
// and `strata gc --keep-last`, SIGKILLed at random moments. Every map afterwards opens, checks
// clean and is exactly one of the two states: before the command or after it. Run serially
// (CTest RUN_SERIAL): the kill times are measured on the machine and must not be stretched by
// other tests.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>

#include "CliTestUtil.hpp"
#include "Format4Map.hpp"
#include "StoreFaultUtil.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools::test {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kSessions = 10;        // the migration target: a 10-session format-4 map
constexpr double kKillSpread = 1.3;  // kill times spread over 1.3x the measured run

// A format-5 map of kSessions sessions, its fused map after each session, and the same map
// rewritten as format 4 beside it.
struct Maps {
    fs::path current;  // the current format
    fs::path format4;
    std::vector<core::VoxelMap> after;  // [k]: the fused map after session k + 1
};

const Maps& TenSessions() {
    static const Maps maps = [] {
        Maps m{Temp("kills_v5") / "map", Temp("kills_v4") / "map", {}};
        const fs::path seq = MakeSequence(Temp("kills_seq"), FaultSequence());
        for (int s = 1; s <= kSessions; ++s) {
            const Result r = Strata(Join(IntegrateArgs(m.current, seq, s)));
            EXPECT_EQ(r.code, 0) << r.out;
            const store::MapStore map = OpenForReading(m.current);
            m.after.push_back(map.LoadMap(map.Latest()));
        }
        fs::create_directories(m.format4.parent_path());
        fs::copy(m.current, m.format4, fs::copy_options::recursive);
        strata::test::RewriteAsFormat4(m.format4);
        return m;
    }();
    return maps;
}

// A fresh copy of `from` to run a command on.
fs::path CopyOf(const fs::path& from, const std::string& name) {
    const fs::path to = Temp(name) / "map";
    fs::remove_all(to.parent_path());
    fs::create_directories(to.parent_path());
    fs::copy(from, to, fs::copy_options::recursive);
    return to;
}

// Runs `args` on fresh copies, killed at uniformly random times over kKillSpread x its measured
// duration; `verify` judges each map left behind (the outcome says whether it was killed).
void KillAtRandom(const fs::path& from, const std::vector<std::string>& args_before_map,
                  const std::vector<std::string>& args_after_map,
                  const std::function<void(const fs::path&, const Outcome&)>& verify) {
    const auto args = [&](const fs::path& map) {
        std::vector<std::string> all = args_before_map;
        all.push_back(map.string());
        all.insert(all.end(), args_after_map.begin(), args_after_map.end());
        return all;
    };
    const fs::path log = Temp("kills.log");
    const fs::path timed = CopyOf(from, "kills_timed");
    const Outcome full = Wait(Spawn(args(timed), log));
    ASSERT_EQ(full.code, 0) << ReadText(log);
    std::mt19937 rng(Seed());
    std::uniform_real_distribution<double> when(0.0, kKillSpread * full.seconds);
    int killed = 0;
    for (int attempt = 0; attempt < KillAttempts(); ++attempt) {
        const fs::path map = CopyOf(from, "kills_attempt");
        const double delay_s = when(rng);
        const Child child = Spawn(args(map), log);
        const Outcome out =
            KillAt(child, child.start + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(delay_s)));
        SCOPED_TRACE("attempt " + std::to_string(attempt) + ": kill at " + std::to_string(delay_s) +
                     " s of " + std::to_string(full.seconds) +
                     " s: " + (out.killed ? "killed" : "exited " + std::to_string(out.code)));
        if (!out.killed) {
            ASSERT_EQ(out.code, 0) << ReadText(log);
        }
        killed += out.killed;
        verify(map, out);
        if (::testing::Test::HasFatalFailure()) return;
    }
    // How many kills land inside the run depends on the machine's load (ctest -j): reported,
    // and only "at least one" asserted, or the loop proved nothing.
    std::printf("%d attempts: %d killed mid-run\n", KillAttempts(), killed);
    EXPECT_GE(killed, 1);
}

// Killed during `strata upgrade`: the map is format 4, untouched (its files intact; upgrading it
// again gives the same current map), or format 5 or later and complete (4 -> 5 moves the files,
// each later step commits on its own). A map left between two later steps (format 5 of 6: the
// kill landed after the 4 -> 5 commit, as in a cold CI run on 2026-12-08) is refused by the
// commands that only read, with the advice to upgrade, and `strata upgrade` finishes it.
TEST(StoreFaults, KilledUpgradesLeaveTheOldFormatOrTheNew) {
    const Maps& maps = TenSessions();
    ASSERT_EQ(maps.after.size(), static_cast<size_t>(kSessions));
    const auto format4_files = MapFiles(maps.format4);
    int old_format = 0, new_format = 0, between = 0;
    KillAtRandom(maps.format4, {"upgrade"}, {}, [&](const fs::path& map, const Outcome& out) {
        const int format = store::MapStore::FormatOf(map);
        ASSERT_TRUE(format >= 4 && format <= store::MapStore::kFormatVersion) << format;
        if (format == 4) {
            ++old_format;
            ASSERT_TRUE(out.killed);
            // Every format-4 file as it was; anything new is garbage the upgrade rewrites.
            const auto files = MapFiles(map);
            for (const auto& [file, bytes] : format4_files) {
                const auto it = files.find(file);
                ASSERT_TRUE(it != files.end() && it->second == bytes) << file;
            }
            const Result again = Strata("upgrade " + map.string());
            ASSERT_EQ(again.code, 0) << again.out;
        } else {
            ++new_format;
        }
        if (format > 4 && format < store::MapStore::kFormatVersion) {
            ++between;
            ASSERT_TRUE(out.killed);
            const Result refused = Strata("check " + map.string());
            EXPECT_NE(refused.code, 0) << refused.out;
            EXPECT_NE(refused.out.find("run `strata upgrade "), std::string::npos) << refused.out;
            const Result again = Strata("upgrade " + map.string());
            ASSERT_EQ(again.code, 0) << again.out;
            ASSERT_EQ(store::MapStore::FormatOf(map), store::MapStore::kFormatVersion);
        }
        const Result check = Strata("check " + map.string() + " --json");
        ASSERT_EQ(check.code, 0) << check.out;
        const store::MapStore store = OpenForReading(map);
        for (int s = 1; s <= kSessions; s += 3) {
            ASSERT_TRUE(SameMap(store.LoadMap(store.AsOf(s)), maps.after[s - 1]))
                << "session " << s;
        }
        ASSERT_TRUE(SameMap(store.LoadMap(store.Latest()), maps.after.back()));
        ASSERT_EQ(store.SessionLayers(kSessions).size(),
                  OpenForReading(maps.current).SessionLayers(kSessions).size());
    });
    std::printf("upgrade kills: %d left format 4, %d format 5 or later (%d of them before %d)\n",
                old_format, new_format, between, store::MapStore::kFormatVersion);
    EXPECT_GE(old_format, 1);
    EXPECT_GE(new_format, 1);
}

// Killed during `strata gc --keep-last 3`: the history is whole, or starts three commits back;
// the current map is the same either way and nothing is damaged.
TEST(StoreFaults, KilledHistoryDropsLeaveTheHistoryBeforeOrAfter) {
    const Maps& maps = TenSessions();
    const int64_t latest = OpenForReading(maps.current).Latest().commit;
    int before = 0, after = 0;
    KillAtRandom(
        maps.current, {"gc"}, {"--keep-last", "3"}, [&](const fs::path& map, const Outcome&) {
            const Result check = Strata("check " + map.string() + " --json");
            ASSERT_EQ(check.code, 0) << check.out;
            const store::MapStore store = OpenForReading(map);
            ASSERT_TRUE(SameMap(store.LoadMap(store.Latest()), maps.after.back()));
            const int64_t start = store.HistoryStart();
            ASSERT_TRUE(start == 1 || start == latest - 2) << start;
            if (start == 1) {
                ++before;
                ASSERT_TRUE(SameMap(store.LoadMap(store.AsOf(1)), maps.after[0]));
            } else {
                ++after;
                ASSERT_THROW((void)store.AsOf(1), strata::NotFoundError);
                ASSERT_TRUE(
                    SameMap(store.LoadMap(store.AsOf(kSessions - 2)), maps.after[kSessions - 3]));
            }
            // Whatever a kill left over, the next gc removes, and the map stays the same.
            const Result gc = Strata("gc " + map.string());
            ASSERT_EQ(gc.code, 0) << gc.out;
            ASSERT_TRUE(
                JsonIn(Strata("check " + map.string() + " --json").out)["unreferenced"].empty());
        });
    std::printf("gc kills: history whole %d times, dropped %d times\n", before, after);
    EXPECT_GE(before, 1);
    EXPECT_GE(after, 1);
}

}  // namespace
}  // namespace strata::tools::test
