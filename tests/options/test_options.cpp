// The option table (option_table.cpp) against everything made from it: every option round-trips
// through its text and through a state file, appears in --help and in the EXR metadata, is
// validated at its documented bounds in process and on the command line, follows the resume
// rules of its kind, and docs/usage.md's option table is exactly the one the table makes.
#include "process_fixture.h"
#include "render_fixture.h"

#include "app/checkpoint.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace pb {
namespace {

RenderOptions valid() {
  RenderOptions o;
  o.scene = "s.gltf";
  o.output = "o.exr";
  o.passes = 1;
  return o;
}

// Every option set to its first documented accepted value (not the default where it has more).
RenderOptions all_set() {
  RenderOptions o = valid();
  for (const OptionSpec& s : option_table()) s.parse(o, s.accepted.back());
  o.reference_path.clear();  // --reference needs --log; both set below
  o.log_path = "l.jsonl";
  o.reference_path = "r.exr";
  return o;
}

TEST(Options, EveryOptionRoundTripsThroughItsText) {
  for (const OptionSpec& s : option_table()) {
    SCOPED_TRACE(std::string(s.flag));
    ASSERT_FALSE(s.accepted.empty());
    for (const std::string& v : s.accepted) {
      RenderOptions a = valid();
      s.parse(a, v);
      const std::string text = s.format(a);
      EXPECT_FALSE(text.empty()) << v;
      RenderOptions b = valid();
      s.parse(b, text);
      EXPECT_EQ(s.format(b), text) << v;
    }
    // reset() brings back the default.
    RenderOptions c = valid();
    s.parse(c, s.accepted.back());
    s.reset(c);
    EXPECT_EQ(s.format(c), s.format(RenderOptions{}));
  }
}

class OptionFiles : public test::TempDirTest {};

TEST_F(OptionFiles, OptionsRoundTripThroughTheStateFile) {
  SavedRender saved;
  saved.options = all_set();
  saved.options.scene = path("scene.gltf");
  save_state(path("s.pbstate"), saved);
  const SavedRender loaded = load_state(path("s.pbstate"));
  for (const OptionSpec& s : option_table())
    EXPECT_EQ(s.format(loaded.options), s.format(saved.options)) << s.flag;
  EXPECT_EQ(loaded.options.scene, saved.options.scene);
}

TEST(Options, EveryOptionIsInTheHelpAndTheMetadata) {
  const std::string help = usage_text();
  const auto meta = describe(all_set());
  for (const OptionSpec& s : option_table()) {
    if (s.switches.empty()) {
      EXPECT_NE(help.find("  " + std::string(s.flag) + " "), std::string::npos) << s.flag;
    } else {
      for (const auto& [flag, value] : s.switches)
        EXPECT_NE(help.find(std::string(flag)), std::string::npos) << flag;
    }
    if (!s.range.empty()) EXPECT_NE(help.find(s.range), std::string::npos) << s.flag;
    bool found = false;
    for (const auto& [k, v] : meta) found |= k == s.key && v == s.display(all_set());
    EXPECT_TRUE(found) << s.key;
  }
}

// The ends of every documented range are accepted and one step beyond is refused, in process
// (check) and on the command line (parse), with a one-line message naming the option.
TEST(Options, EveryOptionIsValidatedAtItsDocumentedBounds) {
  for (const OptionSpec& s : option_table()) {
    SCOPED_TRACE(std::string(s.flag));
    for (const std::string& v : s.accepted) {
      RenderOptions o = valid();
      EXPECT_NO_THROW(s.parse(o, v)) << v;
      EXPECT_NO_THROW(s.check(o)) << v;
    }
    for (const std::string& v : s.rejected) {
      RenderOptions o = valid();
      try {
        s.parse(o, v);
        ADD_FAILURE() << "accepted " << v;
      } catch (const UsageError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind(std::string(s.flag) + ": ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      }
    }
    if (!s.switches.empty()) continue;
    // The same through the parser: a flag with each rejected value exits with a UsageError.
    for (const std::string& v : s.rejected) {
      std::vector<const char*> argv = {"photonbound", "render", "s.gltf",      "-o",     "o.exr",
                                       "--passes",    "1",      s.flag.data(), v.c_str()};
      EXPECT_THROW(parse_command_line(int(argv.size()), argv.data()), UsageError) << v;
    }
  }
}

// One table, one rule: `render --resume` and `resume` agree on what may change.
TEST(Options, ResumeFollowsTheKindOfEachOption) {
  const RenderOptions saved = all_set();
  for (const OptionSpec& s : option_table()) {
    if (!s.switches.empty() || s.key == "resume" || s.key == "output") continue;
    SCOPED_TRACE(std::string(s.flag));
    const std::string v = s.accepted.front();
    std::vector<const char*> argv = {"photonbound", "resume",      "x.pbstate", "-o",
                                     "new.exr",     s.flag.data(), v.c_str()};
    if (s.key == "reference") argv.insert(argv.end(), {"--log", "l.jsonl"});
    if (s.kind == OptionKind::Image) {
      EXPECT_THROW(parse_command_line(int(argv.size()), argv.data()), UsageError);
      // ... and a render continued with another value names the difference.
      RenderOptions now = saved;
      s.parse(now, s.accepted.front() == s.format(saved) ? s.accepted.back() : v);
      if (s.format(now) != s.format(saved)) EXPECT_FALSE(image_differences(saved, now).empty());
      continue;
    }
    const Command c = parse_command_line(int(argv.size()), argv.data());
    const RenderOptions r = resumed_options(saved, c.resume);
    EXPECT_EQ(s.format(r), [&] {
      RenderOptions t;
      s.parse(t, v);
      return s.format(t);
    }());
    EXPECT_TRUE(image_differences(saved, r).empty());
    EXPECT_EQ(r.output, "new.exr");
    if (s.kind == OptionKind::Stop) {  // a new stop condition replaces all saved ones
      for (const char* key : {"passes", "time", "target_error"})
        if (key != s.key) EXPECT_EQ(option(key).format(r), "") << key;
    }
  }
  // Without options other than the output: the saved plan, this run's own options at default.
  std::vector<const char*> argv = {"photonbound", "resume", "x.pbstate", "-o", "new.exr"};
  const RenderOptions r =
      resumed_options(saved, parse_command_line(int(argv.size()), argv.data()).resume);
  for (const OptionSpec& s : option_table()) {
    if (s.key == "resume")
      EXPECT_EQ(r.resume_from, "x.pbstate");
    else if (s.kind == OptionKind::Run && s.key != "output")
      EXPECT_EQ(s.format(r), s.format(RenderOptions{})) << s.flag;
    else if (s.kind != OptionKind::Run)
      EXPECT_EQ(s.format(r), s.format(saved)) << s.flag;
  }
}

// The full option table lives in docs/usage.md ("Command line"); README.md only names six options.
TEST(Options, UsageOptionTableIsTheGeneratedOne) {
  std::ifstream f(std::string(PHOTONBOUND_SCENES) + "/../docs/usage.md");
  ASSERT_TRUE(f) << "docs/usage.md not found";
  std::stringstream buf;
  buf << f.rdbuf();
  const std::string usage = buf.str();
  const std::string table = markdown_option_table();
  EXPECT_NE(usage.find(table), std::string::npos)
      << "docs/usage.md's option table differs from `photonbound --help-table`; replace it with:\n"
      << table;
}

}  // namespace
}  // namespace pb
