// `pdvo` interrupted (SIGINT, SIGTERM) while it writes: it ends with 128 + the signal, leaves no staging folder or
// temporary file, and what an earlier run wrote is unchanged.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

extern char** environ;

namespace pdvo {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Runs `pdvo <args>` to its end, its output discarded; returns the exit code.
int RunPdvo(const std::string& args) {
  const int status = std::system((std::string(PDVO_BINARY) + " " + args + " > /dev/null 2>&1").c_str());
  return WEXITSTATUS(status);
}

// Starts `pdvo <args>`, waits until `ready()` holds (at most 60 s), sends `signal`, and returns the exit code.
// -1 if the run ended before it was ready; kKilled if the signal's default action ended it (no cleanup ran), so
// that an exit code of 130 or 143 proves pdvo took the signal and cleaned up.
constexpr int kKilled = -3;

template <class Ready>
int Interrupt(const std::string& args, int signal, Ready ready) {
  const std::string command = "exec " + std::string(PDVO_BINARY) + " " + args + " > /dev/null 2>&1";
  std::vector<char*> argv = {const_cast<char*>("/bin/sh"), const_cast<char*>("-c"), const_cast<char*>(command.c_str()),
                             nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv.data(), environ) != 0) return -2;
  int status = 0;
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (!ready() && Clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return -1;  // ended on its own: too quick to interrupt
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, signal);
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : kKilled;
}

// Every file under `folder` (hidden ones too) with its content.
std::map<std::string, std::string> Contents(const std::string& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), folder).string()] = ReadFile(e.path().string());
  }
  return files;
}

// The names directly in `folder` that contain `part`.
std::vector<std::string> NamesWith(const std::string& folder, const std::string& part) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name.find(part) != std::string::npos) names.push_back(name);
  }
  return names;
}

// True once the staging folder `.NAME.partial-PID` beside `dir/name` holds at least one file.
auto StagingHasFiles(const test::TempDir& dir, const std::string& name) {
  return [&dir, name] {
    for (const std::string& staging : NamesWith(dir.str(), "." + name + ".partial-")) {
      std::error_code ec;
      for (const auto& e : fs::recursive_directory_iterator(dir / staging, ec)) {
        if (e.is_regular_file(ec)) return true;
      }
    }
    return false;
  };
}

const char* kSmall = " --set width=160 --set height=120 -v warning";

TEST(Interrupt, SynthAndVoAndAnnotateDepthLeaveTheEarlierRunAsItWas) {
  test::TempDir dir;
  ASSERT_EQ(RunPdvo("synth -o " + (dir / "s") + " -n 200 --seed 3" + kSmall), 0);
  ASSERT_EQ(RunPdvo("vo -s " + (dir / "s") + " -o " + (dir / "v") + " --max-frames 5 -v warning"), 0);
  const std::string config = std::string(PDVO_SOURCE_DIR) + "/annotations/config/synthetic.yaml";
  const std::string annotate = "annotate-depth --config " + config + " -v warning -o " + (dir / "a") + " --sequence ";
  ASSERT_EQ(RunPdvo("synth -o " + (dir / "short") + " -n 2 --seed 3" + kSmall), 0);
  ASSERT_EQ(RunPdvo(annotate + (dir / "short")), 0);
  const auto before = std::map<std::string, std::map<std::string, std::string>>{
      {"s", Contents(dir / "s")}, {"v", Contents(dir / "v")}, {"a", Contents(dir / "a")}};
  ASSERT_EQ(before.at("s").count(kOutputMarker), 1u);

  // A long synth into the earlier street (SIGINT), the whole street through the odometry (SIGTERM), and
  // annotate-depth on every frame (SIGINT), each stopped once its staging folder holds files.
  EXPECT_EQ(Interrupt("synth -o " + (dir / "s") + " -n 3000 --seed 4" + kSmall, SIGINT, StagingHasFiles(dir, "s")),
            130);
  EXPECT_EQ(Interrupt("vo -s " + (dir / "s") + " -o " + (dir / "v") + " --overlay -v warning", SIGTERM,
                      StagingHasFiles(dir, "v")),
            143);
  EXPECT_EQ(Interrupt(annotate + (dir / "s"), SIGINT, StagingHasFiles(dir, "a")), 130);
  for (const char* name : {"s", "v", "a"}) {
    EXPECT_EQ(Contents(dir / name), before.at(name)) << name << ": the interrupted run changed the earlier output";
  }
  EXPECT_EQ(NamesWith(dir.str(), ".partial-"), std::vector<std::string>{}) << "staging folders left behind";
}

TEST(Interrupt, InterruptedTrainingLeavesTheEarlierModelAndNoTemporaryFile) {
  test::TempDir dir;
  ASSERT_EQ(RunPdvo("synth -o " + (dir / "s") + " -n 40 --seed 11 --set walk.fps=3" + std::string(kSmall)), 0);
  WriteFileAtomically(dir / "m.yml", "an earlier model\n");
  const auto start = Clock::now();
  const auto after_a_second = [start] { return Clock::now() - start > std::chrono::seconds(1); };
  EXPECT_EQ(Interrupt("train -a " + (dir / "s/annotations") + " -o " + (dir / "m.yml") + " -v warning", SIGINT,
                      after_a_second),
            130);
  EXPECT_EQ(ReadFile(dir / "m.yml"), "an earlier model\n");
  EXPECT_EQ(NamesWith(dir.str(), ".tmp"), std::vector<std::string>{});
}

TEST(Interrupt, ASecondRunLeavesNothingOfTheFirst) {
  test::TempDir dir;
  ASSERT_EQ(RunPdvo("synth -o " + (dir / "s") + " -n 6 --seed 3" + std::string(kSmall)), 0);
  ASSERT_EQ(RunPdvo("synth -o " + (dir / "s") + " -n 2 --seed 3" + std::string(kSmall)), 0);
  EXPECT_EQ(NamesWith(dir / "s/rgb", ".png").size(), 2u);
  EXPECT_EQ(NamesWith(dir / "s/annotations", ".json").size(), 2u);
  // A folder the user made is refused, and kept as it was.
  WriteFileAtomically(dir / "mine/notes.txt", "mine");
  EXPECT_EQ(RunPdvo("synth -o " + (dir / "mine") + " -n 2" + std::string(kSmall)), 2);
  EXPECT_EQ(Contents(dir / "mine"), (std::map<std::string, std::string>{{"notes.txt", "mine"}}));
}

}  // namespace
}  // namespace pdvo
