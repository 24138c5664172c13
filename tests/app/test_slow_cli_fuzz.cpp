// Every option with hostile values: each gives exit code 2 and a one-line message, never a
// crash or a hang (issue "Numerically sound at the extremes": options fuzzed from the CLI side).
#include "process_fixture.h"

#include <filesystem>
#include <set>
#include <string>

namespace {

namespace fs = std::filesystem;
using pb::test::Outcome;

Outcome run_in(const fs::path& dir, const std::string& args) {
  return pb::test::run_photonbound(args, dir.string());
}

TEST(SlowCliFuzz, HostileValuesGiveUsageErrors) {
  const fs::path dir = pb::test::unique_temp_path("cli_fuzz");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(PHOTONBOUND_SCENES) + "/plane_point.gltf";
  const std::string base =
      "render '" + scene + "' -o out.exr --resolution 8x8 --photons-per-pass 100 ";
  const char* flags[] = {
      "--passes", "--time",       "--target-error", "--photons-per-pass", "--alpha",
      "--radius", "--max-depth",  "--resolution",   "--threads",          "--seed",
      "--direct", "--confidence", "--min-passes",   "--error-metric",     "--checkpoint-every"};
  // Shell-quoted: empty, negative, NaN, infinities, overflow, non-numeric, hex, padded, a flag.
  const char* values[] = {"''",
                          "-1",
                          "nan",
                          "-inf",
                          "1e400",
                          "abc",
                          "0x10",
                          "' 3'",
                          "'3 '",
                          "--",
                          "99999999999999999999999"};
  // Values that are legitimately in range for a flag (checked to succeed instead).
  const std::set<std::pair<std::string, std::string>> valid = {
      {"--radius", "99999999999999999999999"}, {"--target-error", "99999999999999999999999"}};
  for (const char* flag : flags) {
    for (const char* value : values) {
      const bool ok = valid.count({flag, value}) > 0;
      const std::string stop = std::string(flag) == "--passes" ? "" : "--passes 1 ";
      const Outcome r = run_in(dir, base + stop + flag + " " + value);
      if (ok) {
        EXPECT_EQ(r.code, 0) << flag << " " << value << ": " << r.err;
        continue;
      }
      EXPECT_EQ(r.code, 2) << flag << " " << value << ": " << r.err;
      EXPECT_FALSE(r.err.empty()) << flag << " " << value;
      EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << flag << " " << value << ": " << r.err;
    }
    // The flag as the last word, with no value at all.
    const Outcome r = run_in(dir, base + "--passes 1 " + flag);
    EXPECT_EQ(r.code, 2) << flag << " without a value: " << r.err;
  }
  fs::remove_all(dir);
}

}  // namespace
