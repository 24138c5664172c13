// Checkpoints, resume and interruption (docs/usage.md "Checkpoints and interruption").
#include "process_fixture.h"
#include "render_fixture.h"
#include "resume_check.h"

#include "app/checkpoint.h"
#include "app/checkpoint_writer.h"
#include "io/image_io.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

namespace pb {
namespace {

namespace fs = std::filesystem;

class Checkpoints : public test::TempDirTest {};

RenderOptions small_options() {
  RenderOptions o = test::quick_options("cornell.gltf", 32, 8);
  o.photons_per_pass = 10000;
  return o;
}

TEST_F(Checkpoints, ResumeIsBitIdentical) {
  expect_resume_bit_identical(small_options(), path("half.pbstate"));
}

// SPPM: the per-pixel states, visible-pass counters and kernel masses go through the state file
// too, and the camera paths after the resume are keyed by the same (seed, pass, pixel).
TEST_F(Checkpoints, ResumeIsBitIdenticalWithSppm) {
  RenderOptions o = small_options();
  o.method = Method::SPPM;
  expect_resume_bit_identical(o, path("half.pbstate"));
}

// --adaptive photons: the photon guide's histogram goes through the state file, so the photons
// after the resume are drawn from the guide the uninterrupted render had.
TEST_F(Checkpoints, ResumeIsBitIdenticalWithGuidedPhotons) {
  RenderOptions o = small_options();
  o.method = Method::SPPM;
  o.adaptive_photons = true;
  expect_resume_bit_identical(o, path("half.pbstate"));
  const SavedRender s = saved_after(o, 2);
  EXPECT_EQ(s.render.guide_learnt, 2u);
  save_state(path("g.pbstate"), s);
  const SavedRender t = load_state(path("g.pbstate"));
  EXPECT_EQ(t.render.guide, s.render.guide);
  EXPECT_EQ(t.render.guide_learnt, 2u);
  // A guided state does not resume a render without the guide.
  o.adaptive_photons = false;
  const Scene scene = load_gltf(o.scene);
  Renderer plain(scene, o);
  EXPECT_THROW(plain.restore(t.render), StateError);
}

// --adaptive paths: each pixel's path history (PathHistory) goes through the state file, so the
// paths after the resume are the uninterrupted render's; resumed after pass 19, when pixels have
// had several paths.
TEST_F(Checkpoints, ResumeIsBitIdenticalWithAdaptivePaths) {
  RenderOptions o = small_options();
  o.method = Method::SPPM;
  o.adaptive_paths = true;
  o.passes = 22;
  expect_resume_bit_identical(o, path("paths.pbstate"), 19);
  const SavedRender s = saved_after(o, 19);
  float dof = 0.0f;
  for (size_t k = 2; k < s.render.path_history.size(); k += 3) dof += s.render.path_history[k];
  EXPECT_GT(dof, 0.0f);  // some pixel had several paths before the state was written
  o.adaptive_paths = false;
  const Scene scene = load_gltf(o.scene);
  Renderer plain(scene, o);
  EXPECT_THROW(plain.restore(s.render), StateError);
}

// --confidence is an option a resume may change (it adjusts the stop and the report): the
// paths' allocation, which weighs the sparse-photon bound at a confidence, must not follow it,
// or the resumed image would not be the uninterrupted one's. The caustic's floor has pixels
// with 0-2 photons (with the allocation following --confidence, 0.5 moved this image by 8e-5
// in the mean).
TEST_F(Checkpoints, ConfidenceDoesNotChangeWhichPathsAreTraced) {
  RenderOptions o = test::quick_options("caustic.gltf", 32, 20);
  o.photons_per_pass = 10000;
  o.method = Method::SPPM;
  o.adaptive_paths = true;
  const Scene scene = load_gltf(o.scene);
  Renderer a(scene, o);
  o.confidence = 0.5;
  Renderer b(scene, o);
  for (int k = 0; k < 20; ++k) {
    a.step();
    b.step();
  }
  ASSERT_EQ(a.states().size(), b.states().size());
  for (size_t k = 0; k < a.states().size(); ++k) {
    ASSERT_EQ(a.states()[k].mean_x, b.states()[k].mean_x) << "state " << k;
    ASSERT_EQ(a.states()[k].r2, b.states()[k].r2) << "state " << k;
  }
}

// Checkpoints written on the background thread: each snapshot is the render exactly as one pass
// left it (its states equal a render stepped to that pass), checkpointing does not change the
// render, and resuming from any snapshot finishes bit-identical to the uninterrupted render.
TEST_F(Checkpoints, BackgroundSnapshotsAreExactAndResumeBitIdentical) {
  RenderOptions o = small_options();
  o.passes = 10;
  const Scene scene = load_gltf(o.scene);
  Renderer straight(scene, o);
  test::run_to_stop(straight);
  const size_t bytes = straight.states().size() * sizeof(PointState);

  std::mutex m;
  std::vector<SavedRender> snaps;
  // Every 1e-9 s: whenever the writer is idle.
  CheckpointWriter writer(1e-9, o, 0, [&](const SavedRender& s) {
    std::lock_guard<std::mutex> lock(m);
    snaps.push_back(s);
  });
  Renderer checkpointed(scene, o);
  PassObserver* observers[] = {&writer};
  Driver(checkpointed).run(nullptr, observers);
  EXPECT_EQ(std::memcmp(checkpointed.states().data(), straight.states().data(), bytes), 0);
  // The writer is idle at pass 1, so there is at least that snapshot; how many more depends on
  // scheduling, and each is checked the same way.
  ASSERT_GE(snaps.size(), 1u);
  EXPECT_EQ(snaps.front().render.work.passes, 1u);
  EXPECT_EQ(writer.checkpoints(), snaps.size());

  for (const SavedRender& s : snaps) {
    SCOPED_TRACE("snapshot after pass " + std::to_string(s.render.work.passes));
    ASSERT_LT(s.render.work.passes, *o.passes);      // the last pass is the caller's to write
    EXPECT_EQ(s.schedule.next_check, o.min_passes);  // the driver's schedule is saved too
    Renderer stepped(scene, o);
    while (stepped.passes() < s.render.work.passes) stepped.step();
    EXPECT_EQ(std::memcmp(s.render.states.data(), stepped.states().data(), bytes), 0);
    Renderer resumed(scene, o);
    resumed.restore(s.render);
    test::run_to_stop(resumed, s.schedule);
    EXPECT_EQ(std::memcmp(resumed.states().data(), straight.states().data(), bytes), 0);
  }
}

// A write that fails is reported by run(), not lost on the background thread.
TEST_F(Checkpoints, FailedBackgroundWriteIsRethrown) {
  RenderOptions o = small_options();
  o.passes = 6;
  const Scene scene = load_gltf(o.scene);
  CheckpointWriter writer(1e-9, o, 0, [](const SavedRender&) {
    throw StateError("out.pbstate: cannot write (No space left on device)");
  });
  Renderer r(scene, o);
  PassObserver* observers[] = {&writer};
  try {
    Driver(r).run(nullptr, observers);
    ADD_FAILURE() << "run() returned";
  } catch (const StateError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos);
  }
}

TEST_F(Checkpoints, StateRoundTripsExactly) {
  const SavedRender s = saved_after(small_options(), 2);
  save_state(path("s.pbstate"), s);
  const SavedRender t = load_state(path("s.pbstate"));
  EXPECT_EQ(t.render.work.passes, 2u);
  EXPECT_EQ(t.scene_hash, s.scene_hash);
  EXPECT_EQ(t.options.seed, s.options.seed);
  EXPECT_EQ(t.options.width, s.options.width);
  ASSERT_EQ(t.render.states.size(), s.render.states.size());
  EXPECT_EQ(std::memcmp(t.render.states.data(), s.render.states.data(),
                        s.render.states.size() * sizeof(PointState)),
            0);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const StateError& e) {
    return e.what();
  }
  return "";
}

TEST_F(Checkpoints, BadStateFilesAreRefusedWithTheirReason) {
  save_state(path("good.pbstate"), saved_after(small_options(), 1));
  std::ifstream in(path("good.pbstate"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(path(name), std::ios::binary) << content;
    return path(name);
  };
  const std::string truncated = write("truncated.pbstate", bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(error_of([&] { load_state(truncated); }).find("truncated"), std::string::npos);
  const std::string stub = write("stub.pbstate", bytes.substr(0, 20));
  EXPECT_NE(error_of([&] { load_state(stub); }).find("truncated"), std::string::npos);

  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  const std::string corrupted = write("corrupted.pbstate", flipped);
  EXPECT_NE(error_of([&] { load_state(corrupted); }).find("checksum"), std::string::npos);

  std::string other_version = bytes;
  other_version[8] = char(kStateVersion + 1);
  const std::string version = write("version.pbstate", other_version);
  EXPECT_NE(error_of([&] { load_state(version); }).find("version"), std::string::npos);

  const std::string text = write("text.pbstate", "hello, I am not a state file at all\n");
  EXPECT_NE(error_of([&] { load_state(text); }).find("not a photonbound state"), std::string::npos);
  EXPECT_NE(error_of([&] { load_state(path("missing.pbstate")); }).find("cannot open"),
            std::string::npos);
  // Every message names the file.
  EXPECT_NE(error_of([&] { load_state(corrupted); }).find("corrupted.pbstate"), std::string::npos);
}

TEST_F(Checkpoints, MismatchedSceneAndOptionsAreNamed) {
  const RenderOptions o = small_options();
  const SavedRender s = saved_after(o, 1);
  EXPECT_TRUE(differences(s, o, s.scene_hash).empty());
  RenderOptions changed = o;
  changed.alpha = 0.5;
  changed.seed = 9;
  const auto d = differences(s, changed, s.scene_hash);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0], "alpha: 0.7 in the state, 0.5 now");
  EXPECT_EQ(d[1], "seed: 1 in the state, 9 now");
  const auto scene = differences(s, o, s.scene_hash + 1);
  ASSERT_EQ(scene.size(), 1u);
  EXPECT_NE(scene[0].find("scene"), std::string::npos);
  // Options that do not change the image may differ.
  RenderOptions harmless = o;
  harmless.threads = 1;
  harmless.passes = 1000;
  harmless.confidence = 0.5;
  EXPECT_TRUE(differences(s, harmless, s.scene_hash).empty());
  // A state whose points do not fit the camera is refused by restore.
  RenderOptions other = o;
  other.width = 16;
  other.height = 16;
  const Scene sc = load_gltf(o.scene);
  Renderer r(sc, other);
  EXPECT_THROW(r.restore(s.render), StateError);
}

// ---- The executable under signals -------------------------------------------------------

using test::spawn;
using test::wait_for;
using test::wait_for_handler;

std::string meta(const ExrImage& img, const std::string& key) {
  for (const auto& [k, v] : img.metadata)
    if (k == key) return v;
  return "";
}

std::vector<std::string> long_render(const std::string& out, double every) {
  std::vector<std::string> a = {"photonbound",
                                "render",
                                test::scene_path("cornell.gltf"),
                                "-o",
                                out,
                                "--passes",
                                "1000000",
                                "--resolution",
                                "48x48",
                                "--photons-per-pass",
                                "20000",
                                "--quiet"};
  if (every > 0.0) {
    a.push_back("--checkpoint-every");
    a.push_back(std::to_string(every));
  }
  return a;
}

// kill -9 at arbitrary moments never leaves a half-written image or state: each is renamed
// into place complete, and the state never claims passes the image lacks.
TEST_F(Checkpoints, KillNineLeavesLoadableFiles) {
  const std::string out = path("k.exr"), state = path("k.pbstate");
  for (int trial = 0; trial < 5; ++trial) {
    // A fresh start each trial: the previous trial's state would satisfy wait_for() at once
    // and would be compared with this trial's (younger) image.
    fs::remove(out);
    fs::remove(state);
    const pid_t pid = spawn(long_render(out, 0.02));
    ASSERT_GT(pid, 0);
    ASSERT_TRUE(wait_for(state));
    // A different moment in each trial: 0 to 400 ms after the first checkpoint.
    std::this_thread::sleep_for(std::chrono::milliseconds(37 + 91 * trial));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    const SavedRender s = load_state(state);
    const ExrImage img = read_exr(out);
    EXPECT_GE(std::stoull(meta(img, "passes_done")), s.render.work.passes) << "trial " << trial;
    EXPECT_GT(s.render.work.passes, 0u);
  }
}

// Sends SIGINT `ms` after the render has installed its handler; the render must exit 0.
void interrupt_and_expect_exit_zero(pid_t pid, int ms) {
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for_handler(pid, SIGINT));
  std::this_thread::sleep_for(std::chrono::milliseconds(ms));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST_F(Checkpoints, CtrlCWritesImageAndStateAndExitsZero) {
  const std::string out = path("i.exr"), state = path("i.pbstate");
  const pid_t pid = spawn(long_render(out, 0.0));
  ASSERT_NO_FATAL_FAILURE(interrupt_and_expect_exit_zero(pid, 1500));
  const ExrImage img = read_exr(out);
  EXPECT_EQ(meta(img, "stop_reason"), "interrupted");
  const SavedRender s = load_state(state);
  EXPECT_EQ(std::to_string(s.render.work.passes), meta(img, "passes_done"));
}

// Ctrl-C in the middle of a pass (passes of 400,000 photons, polled every 2,048): the pass is
// discarded, and the image and state are those of the render stopped after its last whole pass,
// bit for bit, as the state's own options render that many passes in this process. Where the
// signal lands does not matter: every pass is either whole or absent.
TEST_F(Checkpoints, CtrlCMidPassKeepsTheLastWholePass) {
  const std::string out = path("m.exr"), state = path("m.pbstate");
  const pid_t pid =
      spawn({"photonbound", "render", test::scene_path("cornell.gltf"), "-o", out, "--passes",
             "1000000", "--resolution", "24x24", "--photons-per-pass", "400000", "--quiet"});
  ASSERT_NO_FATAL_FAILURE(interrupt_and_expect_exit_zero(pid, 2500));
  const ExrImage img = read_exr(out);
  EXPECT_EQ(meta(img, "stop_reason"), "interrupted");
  const SavedRender s = load_state(state);
  EXPECT_EQ(std::to_string(s.render.work.passes), meta(img, "passes_done"));
  Renderer whole(load_gltf(s.options.scene), s.options);
  for (uint64_t k = 0; k < s.render.work.passes; ++k) whole.step();
  const RenderState w = whole.snapshot();
  EXPECT_EQ(w.work.photons, s.render.work.photons);
  EXPECT_EQ(w.work.rays, s.render.work.rays);
  EXPECT_EQ(w.max_photon_power, s.render.max_photon_power);
  EXPECT_EQ(w.visible, s.render.visible);
  ASSERT_EQ(w.states.size(), s.render.states.size());
  EXPECT_EQ(
      std::memcmp(w.states.data(), s.render.states.data(), w.states.size() * sizeof(PointState)),
      0);
  // Channel by channel (the file keeps them in its own order), bit for bit.
  const ExrImage mine = whole.image(RunInfo{});
  ASSERT_EQ(mine.pixels.size(), img.pixels.size());
  const size_t pixels = size_t(img.width) * size_t(img.height), nc = img.channels.size();
  for (size_t c = 0; c < mine.channels.size(); ++c) {
    const int at = img.channel_index(mine.channels[c]);
    ASSERT_GE(at, 0) << mine.channels[c];
    size_t differ = 0;
    for (size_t p = 0; p < pixels; ++p)
      differ += std::memcmp(&mine.pixels[p * nc + c], &img.pixels[p * nc + size_t(at)], 4) != 0;
    EXPECT_EQ(differ, 0u) << mine.channels[c];
  }
}

TEST_F(Checkpoints, SecondSignalLeavesAtOnceAndKeepsTheLastFiles) {
  const std::string out = path("d.exr"), state = path("d.pbstate");
  const pid_t pid = spawn(long_render(out, 0.05));
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for(state));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  kill(pid, SIGTERM);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  // Either the second signal arrived during the last pass (exit 128 + SIGTERM) or the first
  // already finished the pass and its files (exit 0); in both cases the files on disk load.
  EXPECT_TRUE(WEXITSTATUS(status) == 128 + SIGTERM || WEXITSTATUS(status) == 0)
      << WEXITSTATUS(status);
  EXPECT_NO_THROW(load_state(state));
  EXPECT_NO_THROW(read_exr(out));
}

// A render started with a relative scene path resumes from another working directory: the
// state keeps the scene's absolute path.
TEST_F(Checkpoints, ResumeFromAnotherFolderFindsTheScene) {
  fs::create_directories(dir_ / "a");
  fs::copy_file(test::scene_path("cornell.gltf"), dir_ / "a" / "cornell.gltf");
  const test::Outcome first = test::run_photonbound(
      "render cornell.gltf -o ../r.exr --passes 3 --resolution 16x16 --photons-per-pass 1000 "
      "--checkpoint-every 1000 --quiet",
      (dir_ / "a").string());
  ASSERT_EQ(first.code, 0) << first.err;
  const SavedRender s = load_state(path("r.pbstate"));
  EXPECT_TRUE(fs::path(s.options.scene).is_absolute()) << s.options.scene;
  const test::Outcome second =
      test::run_photonbound("resume r.pbstate -o r2.exr --passes 5 --quiet", dir_.string());
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_EQ(meta(read_exr(path("r2.exr")), "passes_done"), "5");
}

}  // namespace
}  // namespace pb
