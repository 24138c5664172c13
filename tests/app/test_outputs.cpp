// Outputs that would destroy an input or cannot be written are refused before the render
// (docs/usage.md "Outputs and refusals"), a second render of the same outputs is locked out,
// SIGHUP ends a render like SIGTERM, no temporary survives, and compare --json is JSON.
#include "app/compare.h"
#include "estimator/channels.h"
#include "io/image_io.h"
#include "process_fixture.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pb::test::Outcome;
using pb::test::quote;

const char* kQuick = " --resolution 8x8 --photons-per-pass 1000 --passes 2 --quiet";
const char* kLong = " --resolution 8x8 --photons-per-pass 1000 --time 30 --quiet";

std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::string scene_source(const std::string& name) {
  return std::string(PHOTONBOUND_SCENES) + "/" + name;
}

// A child photonbound with its stdout and stderr in `log`.
pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>(PHOTONBOUND_EXE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(PHOTONBOUND_EXE, argv.data());
    ::_exit(127);
  }
  return pid;
}

// The child's exit code, -1 when it did not exit within `seconds` (then it is killed) or was
// killed by a signal.
int wait_exit(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

bool wait_for_file(const std::string& path, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (fs::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

class Outputs : public pb::test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fs::copy_file(scene_source("cornell.gltf"), scene());
    scene_bytes_ = read_bytes(scene());
  }
  std::string scene() const { return path("scene.gltf"); }
  std::string out() const { return path("out.exr"); }
  Outcome run(const std::string& args) const { return pb::test::run_photonbound(args); }
  Outcome render(const std::string& args) const {
    return run("render " + quote(scene()) + " " + args + kQuick);
  }
  // A small render of the scene at `where` (an image to use as a map or a reference).
  void make_image(const std::string& where) const {
    const std::string state = where + ".pbstate";
    ASSERT_EQ(run("render " + quote(scene()) + " -o " + quote(where) + " --state " + quote(state) +
                  kQuick)
                  .code,
              0);
    fs::remove(state);
  }
  // The folder holds exactly `names` (no output, no lock file, no temporary).
  void expect_only(std::vector<std::string> names) const {
    std::vector<std::string> have;
    for (const auto& e : fs::directory_iterator(dir_)) have.push_back(e.path().filename().string());
    std::sort(have.begin(), have.end());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(have, names);
  }
  void expect_scene_unchanged() const { EXPECT_EQ(read_bytes(scene()), scene_bytes_); }
  std::string scene_bytes_;
};

void expect_line(const Outcome& r, int code, const std::string& line) {
  EXPECT_EQ(r.code, code) << r.err;
  EXPECT_EQ(r.err, line + "\n");
}

TEST_F(Outputs, StateThatIsTheSceneIsRefused) {
  const Outcome r = render("-o " + quote(out()) + " --state " + quote(scene()));
  expect_line(r, 2, "photonbound: --state " + scene() + " is the scene file: choose another path");
  expect_scene_unchanged();
  expect_only({"scene.gltf"});
}

TEST_F(Outputs, LogThatIsTheSceneIsRefused) {
  const Outcome r = render("-o " + quote(out()) + " --log " + quote(scene()));
  expect_line(r, 2, "photonbound: --log " + scene() + " is the scene file: choose another path");
  expect_scene_unchanged();
  expect_only({"scene.gltf"});
}

TEST_F(Outputs, OutputThatIsTheEnvironmentMapIsRefused) {
  const std::string sky = path("sky.exr");
  make_image(sky);
  const std::string before = read_bytes(sky);
  const Outcome r = render("-o " + quote(sky) + " --environment " + quote(sky));
  expect_line(r, 2, "photonbound: -o " + sky + " is the --environment map: choose another path");
  EXPECT_EQ(read_bytes(sky), before);
  expect_only({"scene.gltf", "sky.exr"});
}

TEST_F(Outputs, OutputThatIsTheReferenceIsRefused) {
  const std::string ref = path("ref.exr");
  make_image(ref);
  const std::string before = read_bytes(ref);
  const Outcome r = render("-o " + quote(ref) + " --log " + quote(path("l.jsonl")) +
                           " --reference " + quote(ref));
  expect_line(r, 2, "photonbound: -o " + ref + " is the --reference image: choose another path");
  EXPECT_EQ(read_bytes(ref), before);
  expect_only({"scene.gltf", "ref.exr"});
}

TEST_F(Outputs, HardLinkToTheReferenceIsRefused) {
  const std::string ref = path("ref.exr"), link = path("link.exr");
  make_image(ref);
  fs::create_hard_link(ref, link);
  const std::string before = read_bytes(ref);
  const Outcome r = render("-o " + quote(link) + " --log " + quote(path("l.jsonl")) +
                           " --reference " + quote(ref));
  expect_line(r, 2,
              "photonbound: -o " + link + " is the --reference image " + ref +
                  " (the same file): choose another path");
  EXPECT_EQ(read_bytes(ref), before);
  expect_only({"scene.gltf", "ref.exr", "link.exr"});
}

TEST_F(Outputs, SymlinkToTheSceneIsRefused) {
  const std::string link = path("link.exr");
  fs::create_symlink(scene(), link);
  const Outcome r = render("-o " + quote(link));
  expect_line(r, 2,
              "photonbound: -o " + link + " is the scene file " + scene() +
                  " (the same file): choose another path");
  expect_scene_unchanged();
  EXPECT_TRUE(fs::is_symlink(link));
  expect_only({"scene.gltf", "link.exr"});
}

TEST_F(Outputs, StateThatIsTheOutputIsRefused) {
  const Outcome r = render("-o " + quote(out()) + " --state " + quote(out()));
  expect_line(r, 2, "photonbound: --state " + out() + " is the path of -o: choose another path");
  expect_only({"scene.gltf"});
}

// The loader's own files (an external .bin) are known only once it read them: still before the
// first pass.
TEST_F(Outputs, StateThatIsAnExternalBufferIsRefused) {
  const std::string gltf = path("ext.gltf"), bin = path("plane_point_external.bin");
  fs::copy_file(scene_source("plane_point_external.gltf"), gltf);
  fs::copy_file(scene_source("plane_point_external.bin"), bin);
  const std::string before = read_bytes(bin);
  const Outcome r = run("render " + quote(gltf) + " -o " + quote(out()) + " --state " + quote(bin) +
                        " --resolution 8x8 --photons-per-pass 1000 --time 30 --quiet");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("photonbound: --state " + bin + " is a file the scene loads", 0), 0u)
      << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_EQ(read_bytes(bin), before);
  expect_only({"scene.gltf", "ext.gltf", "plane_point_external.bin"});
}

TEST_F(Outputs, PreviewOntoItsInputIsRefused) {
  const std::string img = path("r.exr");
  make_image(img);
  const std::string before = read_bytes(img);
  const Outcome r = run("preview " + quote(img) + " -o " + quote(img));
  expect_line(r, 2, "photonbound: -o " + img + " is the input image: choose another path");
  EXPECT_EQ(read_bytes(img), before);
  expect_only({"scene.gltf", "r.exr"});
}

TEST_F(Outputs, OutputMustBeExr) {
  const Outcome r = render("-o " + quote(path("out.jpg")));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(
      r.err.rfind("photonbound: -o " + path("out.jpg") + ": the output must be an OpenEXR", 0), 0u)
      << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  expect_only({"scene.gltf"});
  EXPECT_EQ(render("-o " + quote(path("OUT.EXR"))).code, 0);  // any case
}

TEST_F(Outputs, DirectoryAsOutputIsRefused) {
  fs::create_directory(out());
  const Outcome r = render("-o " + quote(out()));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("photonbound: error: " + out() + ": is a directory, not a regular file", 0),
            0u)
      << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_TRUE(fs::is_directory(out()));
  EXPECT_TRUE(fs::is_empty(out()));
  expect_only({"scene.gltf", "out.exr"});
}

// A fifo is never opened (that would block) nor renamed over.
TEST_F(Outputs, FifoAsStateIsRefused) {
  const std::string fifo = path("s.pbstate");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const Outcome r = render("-o " + quote(out()) + " --state " + quote(fifo));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("photonbound: error: " + fifo + ": is a fifo, not a regular file", 0), 0u)
      << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_TRUE(fs::is_fifo(fifo));
  expect_only({"scene.gltf", "s.pbstate"});
}

// Before the render: with --progress a render that started would print its start line (and
// with --time 30 run for 30 s) before a late failure; the one line on stderr is the refusal.
TEST_F(Outputs, UnwritableStateFolderFailsBeforeTheRender) {
  const fs::path locked = dir_ / "locked";
  fs::create_directory(locked);
  std::string state = (locked / "s.pbstate").string();
  if (::geteuid() == 0)  // root writes anyway: a folder that does not exist instead
    state = (dir_ / "missing" / "s.pbstate").string();
  else
    fs::permissions(locked, fs::perms(0555));
  const Outcome r = run("render " + quote(scene()) + " -o " + quote(out()) + " --state " +
                        quote(state) + " --resolution 8x8 --time 30 --progress");
  fs::permissions(locked, fs::perms(0755));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("photonbound: error: " + state + ": ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_TRUE(fs::is_empty(locked));
  expect_only({"scene.gltf", "locked"});
}

TEST_F(Outputs, SecondRenderOfTheSameOutputIsLockedOut) {
  const pid_t first = spawn({"render", scene(), "-o", out(), "--resolution", "8x8",
                             "--photons-per-pass", "1000", "--time", "30", "--quiet"},
                            path("first.log"));
  ASSERT_TRUE(wait_for_file(out() + ".lock", 10.0));
  const Outcome r = render("-o " + quote(out()));
  // It did not wait for the lock: the first render, running for 30 s unless signalled, is
  // still running when the second has exited.
  int status = 0;
  EXPECT_EQ(::waitpid(first, &status, WNOHANG), 0);
  expect_line(r, 1,
              "photonbound: error: " + out() + ": another photonbound render is writing it (pid " +
                  std::to_string(first) + ")");
  EXPECT_FALSE(fs::exists(out()));
  ::kill(first, SIGTERM);
  EXPECT_EQ(wait_exit(first, 20.0), 0) << read_bytes(path("first.log"));
  EXPECT_TRUE(fs::is_regular_file(out()));
  fs::remove(path("first.log"));
  expect_only({"scene.gltf", "out.exr", "out.pbstate"});  // the lock file is gone
}

TEST_F(Outputs, StaleTemporariesOfADeadRenderAreRemoved) {
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string stale = path(".out.tmp" + std::to_string(dead) + ".exr");
  const std::string stale_state = path(".out.tmp" + std::to_string(dead) + ".pbstate");
  const std::string alive = path(".out.tmp1.exr");  // pid 1 lives: not ours to remove
  for (const std::string& f : {stale, stale_state, alive}) std::ofstream(f) << "partial";
  ASSERT_EQ(render("-o " + quote(out())).code, 0);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_state));
  EXPECT_TRUE(fs::exists(alive));
}

TEST_F(Outputs, CompareJsonIsJsonWithUnknownPixels) {
  // A 2x1 image with an unknown pixel (infinite bound) and an infinite radiance.
  pb::ExrImage img;
  img.width = 2;
  img.height = 1;
  img.channels = pb::channel_names();
  img.pixels.assign(img.channels.size() * 2, 0.5f);
  for (int c = 0; c < 3; ++c) {
    img.pixels[size_t(img.channel_index(pb::channel_name(pb::Channel::ErrorBound, c)))] = INFINITY;
    img.pixels[size_t(img.channel_index(pb::channel_name(pb::Channel::Radiance, c)))] = INFINITY;
  }
  const std::string a = path("a.exr"), json = path("c.json");
  pb::write_exr(a, img);
  const int code = std::system((std::string(PHOTONBOUND_EXE) + " compare " + quote(a) + " " +
                                quote(a) + " --json > " + quote(json))
                                   .c_str());
  ASSERT_EQ(code, 0);
  const std::string text = read_bytes(json);
  EXPECT_NE(text.find("null"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_EQ(text.find("inf"), std::string::npos) << text;
  EXPECT_EQ(
      std::system(("python3 -c 'import json,sys; json.load(sys.stdin)' < " + quote(json)).c_str()),
      0)
      << text;
}

class Signal : public Outputs {};

// A closed terminal (SIGHUP) ends the render like SIGTERM: the pass ends, the image and the
// state are written, exit 0.
TEST_F(Signal, HangupWritesTheImage) {
  const pid_t child = spawn({"render", scene(), "-o", out(), "--resolution", "8x8",
                             "--photons-per-pass", "1000", "--time", "30", "--quiet"},
                            path("run.log"));
  ASSERT_TRUE(wait_for_file(out() + ".lock", 10.0));  // taken after the handlers are installed
  ::kill(child, SIGHUP);
  EXPECT_EQ(wait_exit(child, 20.0), 0) << read_bytes(path("run.log"));
  EXPECT_TRUE(fs::is_regular_file(out()));
  EXPECT_NO_THROW(pb::read_exr(out()));
  fs::remove(path("run.log"));
  expect_only({"scene.gltf", "out.exr", "out.pbstate"});
}

// A second signal exits at once: whatever was being written, no temporary and no lock file is
// left (a checkpoint after every pass keeps writes in flight).
TEST_F(Signal, SecondSignalLeavesNoTemporaries) {
  for (int round = 0; round < 3; ++round) {
    const pid_t child =
        spawn({"render", scene(), "-o", out(), "--resolution", "64x64", "--photons-per-pass",
               "1000", "--time", "30", "--quiet", "--checkpoint-every", "0.001"},
              path("run.log"));
    ASSERT_TRUE(wait_for_file(out() + ".lock", 10.0));
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + 50 * round));
    ::kill(child, SIGTERM);
    std::this_thread::sleep_for(std::chrono::milliseconds(2 * round));
    ::kill(child, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
      EXPECT_EQ(name.find(".lock"), std::string::npos) << name;
    }
  }
}

}  // namespace
