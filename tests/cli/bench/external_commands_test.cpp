// Whole commands run by the bench (cli/bench/external_commands.h): measureCommand's peak memory
// is the command's (a Python process that holds 200 MiB peaks above it, `true` far below it,
// also while this process holds more than that), failures are empty, commandOutput gives what a
// command prints, and lastLine, median and shellQuoted. No figure here is a time.
#include "cli/bench/external_commands.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "tests/support/temp_dir.h"

namespace polydg::bench {
namespace {

constexpr std::size_t kMiB = std::size_t{1} << 20;

/// What `true` may peak at: a shell and a tiny program take a few MiB.
constexpr std::size_t kSmallCommandBytes = 32 * kMiB;

TEST(MeasureCommand, PeakMemoryIsTheCommands) {
  // Python's bytes object of 200 MiB is written through (b'x' * n), so all of it is resident.
  const std::optional<CommandCost> big =
      measureCommand("/usr/bin/python3 -c \"b = b'x' * (200 << 20)\"");
  ASSERT_TRUE(big);
  EXPECT_GE(big->peakRssBytes, 200 * kMiB);
  EXPECT_LT(big->peakRssBytes, 400 * kMiB);  // the interpreter adds some MiB, not another 200
  EXPECT_GE(big->seconds, 0.0);
  const std::optional<CommandCost> small = measureCommand("true");
  ASSERT_TRUE(small);
  EXPECT_GT(small->peakRssBytes, 0u);
  EXPECT_LT(small->peakRssBytes, kSmallCommandBytes);
}

TEST(MeasureCommand, ThisProcesssMemoryDoesNotCount) {
  // A child forked from this process starts with its resident set, and Linux keeps that peak
  // in the child's ru_maxrss across exec: measureCommand must not report it.
  std::vector<char> held(300 * kMiB);
  std::memset(held.data(), 1, held.size());
  const std::optional<CommandCost> small = measureCommand("true");
  ASSERT_TRUE(small);
  EXPECT_LT(small->peakRssBytes, kSmallCommandBytes);
  const std::optional<CommandCost> two = measureCommand("true; true");
  ASSERT_TRUE(two);
  EXPECT_LT(two->peakRssBytes, kSmallCommandBytes);
  EXPECT_EQ(held[held.size() / 2], 1);  // still held
}

TEST(MeasureCommand, FailuresAreEmpty) {
  EXPECT_FALSE(measureCommand("exit 3"));
  EXPECT_FALSE(measureCommand("false"));
  EXPECT_FALSE(measureCommand("polydg-no-such-command-anywhere 2> /dev/null"));
  EXPECT_FALSE(measureCommand("kill -9 $$"));  // killed by a signal
  EXPECT_TRUE(measureCommand("false || true"));
}

TEST(MeasureCommand, RunsTheCommandAsGiven) {
  const polydg::testing::TempDir dir("measure_command");
  const std::string file = (dir.path() / "out.txt").string();
  ASSERT_TRUE(measureCommand("printf '%s\\n' \"it's\" > " + shellQuoted(file) + " && echo two >> " +
                             shellQuoted(file)));
  std::ifstream in(file);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_EQ(first, "it's");
  EXPECT_EQ(second, "two");
}

TEST(CommandOutput, WhatTheCommandPrints) {
  EXPECT_EQ(commandOutput("printf 'a b\\nc\\n'"), std::optional<std::string>("a b\nc\n"));
  EXPECT_EQ(commandOutput("true"), std::optional<std::string>(""));
  EXPECT_FALSE(commandOutput("echo partial; exit 1"));
}

TEST(LastLine, LastLineThatIsNotBlank) {
  const polydg::testing::TempDir dir("last_line");
  EXPECT_EQ(lastLine(dir.write("log", "first\nError: it failed\n\n  \t\n")), "Error: it failed");
  EXPECT_EQ(lastLine(dir.write("one", "only")), "only");
  EXPECT_EQ(lastLine(dir.write("blank", "\n\n")), "");
  EXPECT_EQ(lastLine(dir.path() / "missing"), "");
}

TEST(Median, MiddleOrUpperMiddle) {
  EXPECT_EQ(median({3.0}), 3.0);
  EXPECT_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 3.0);
}

TEST(ShellQuoted, TheShellGivesBackTheText) {
  for (const std::string text : {"plain", "two words", "it's", "$HOME `x` \"q\" \\ *"})
    EXPECT_EQ(commandOutput("printf '%s' " + shellQuoted(text)), std::optional<std::string>(text));
}

}  // namespace
}  // namespace polydg::bench
