#include "pdvo/common/options.h"

#include <gtest/gtest.h>

#include "pdvo/common/camera.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

struct InnerOptions {
  int iterations = 10;
  std::vector<double> weights = {1.0, 2.0};
  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("iterations", self.iterations);
    visit("weights", self.weights);
  }
  bool Check() const {
    PDVO_CHECK_OPTION(iterations > 0);
    return true;
  }
  bool operator==(const InnerOptions&) const = default;
};

struct OuterOptions {
  double threshold = 0.5;
  bool enabled = true;
  std::string mode = "fast";
  InnerOptions inner;
  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("threshold", self.threshold);
    visit("enabled", self.enabled);
    visit("mode", self.mode);
    visit("inner", self.inner);
  }
  bool Check() const {
    PDVO_CHECK_OPTION(threshold >= 0);
    PDVO_CHECK_OPTION(inner.Check());
    return true;
  }
  bool operator==(const OuterOptions&) const = default;
};

TEST(Options, DefaultsAreEqualAndAModifiedCopyDiffers) {
  OuterOptions a, b;
  EXPECT_EQ(a, b);
  b.inner.iterations = 11;
  EXPECT_NE(a, b);
}

TEST(Options, WriteThenReadGivesTheSameOptions) {
  test::TempDir dir;
  OuterOptions written;
  written.threshold = 0.25;
  written.enabled = false;
  written.mode = "slow";
  written.inner.iterations = 3;
  written.inner.weights = {0.5, -1.5, 7};
  SaveOptions(dir / "o.yaml", written, "outer");
  EXPECT_EQ(LoadOptions<OuterOptions>(dir / "o.yaml", "outer"), written);
}

TEST(Options, AbsentKeysKeepDefaults) {
  test::TempDir dir;
  WriteFileAtomically(dir / "o.yaml", "%YAML:1.0\nthreshold: 2.0\n");
  OuterOptions expected;
  expected.threshold = 2.0;
  EXPECT_EQ(LoadOptions<OuterOptions>(dir / "o.yaml"), expected);
}

TEST(Options, UnknownKeyIsAnErrorNamingFileAndKey) {
  test::TempDir dir;
  WriteFileAtomically(dir / "o.yaml", "%YAML:1.0\ninner:\n  iteratoins: 4\n");
  try {
    LoadOptions<OuterOptions>(dir / "o.yaml");
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("o.yaml.inner: unknown key 'iteratoins'"), std::string::npos) << e.what();
  }
}

TEST(Options, WrongTypeIsAnError) {
  test::TempDir dir;
  WriteFileAtomically(dir / "o.yaml", "%YAML:1.0\nthreshold: high\n");
  EXPECT_THROW(LoadOptions<OuterOptions>(dir / "o.yaml"), FormatError);
}

TEST(Options, NonFiniteNumbersAreRefusedNamingTheOption) {
  test::TempDir dir;
  for (const char* value : {".inf", "-.Inf", ".nan"}) {
    WriteFileAtomically(dir / "o.yaml", std::string("%YAML:1.0\nthreshold: ") + value + "\n");
    try {
      LoadOptions<OuterOptions>(dir / "o.yaml");
      ADD_FAILURE() << value << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("threshold: expected a finite number"), std::string::npos) << e.what();
    }
  }
  WriteFileAtomically(dir / "o.yaml", "%YAML:1.0\ninner:\n  weights: [1, .inf]\n");
  EXPECT_THROW(LoadOptions<OuterOptions>(dir / "o.yaml"), FormatError);
  OuterOptions o;
  for (const char* assignment : {"threshold=inf", "threshold=nan", "threshold=1e400", "inner.weights=1,inf"}) {
    EXPECT_THROW(ApplyOverrides(o, {assignment}), InvalidArgument) << assignment;
  }
  EXPECT_EQ(o, OuterOptions());
}

TEST(Options, CheckRejectsBadValues) {
  test::TempDir dir;
  WriteFileAtomically(dir / "o.yaml", "%YAML:1.0\ninner:\n  iterations: 0\n");
  try {
    LoadOptions<OuterOptions>(dir / "o.yaml");
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {  // the file's fault: a data error (exit 2)
    // One message naming the file and the innermost condition that failed, not the outer check of `inner`.
    EXPECT_EQ(std::string(e.what()),
              "invalid options in " + (dir / "o.yaml") + ": iterations > 0 does not hold (inner.iterations = 0)");
  }
  // The next check starts afresh: a failure of the outer options names the outer condition.
  OuterOptions o;
  o.threshold = -1;
  try {
    CheckOptionsOrThrow(o, "outer options");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()), "invalid outer options: threshold >= 0 does not hold (threshold = -1)");
  }
}

TEST(Options, AFailedCheckNamesTheValuesOfWholeNamesOnly) {
  EXPECT_TRUE(detail::MentionsIdentifier("iterations > 0", "iterations"));
  EXPECT_TRUE(detail::MentionsIdentifier("a && (iterations)", "iterations"));
  EXPECT_FALSE(detail::MentionsIdentifier("max_iterations > 0", "iterations"));
  EXPECT_FALSE(detail::MentionsIdentifier("iterations2 > 0", "iterations"));
}

TEST(Options, AssignmentsSetTheSameOptionsAgain) {
  OuterOptions o;
  o.threshold = 0.25;
  o.enabled = false;
  o.mode = "slow";
  o.inner.iterations = 3;
  o.inner.weights = {0.5, 1.5, 2.5};
  std::vector<std::string> assignments;
  OptionAssignments(o, &assignments);
  EXPECT_EQ(assignments, (std::vector<std::string>{"threshold=0.25", "enabled=false", "mode=slow", "inner.iterations=3",
                                                   "inner.weights=0.5,1.5,2.5"}));
  OuterOptions again;
  ApplyOverrides(again, assignments);
  EXPECT_EQ(again, o);
}

// Files that hang OpenCV 4.6's YAML parser (found by fuzzing) or overflow its stack are refused before it sees
// them, with one line naming the file; the project's own files pass.
TEST(Options, YamlThatWouldHangOrCrashOpenCvIsRefused) {
  const test::TempDir dir;
  const auto message_of = [&](const std::string& text) {
    WriteFileAtomically(dir / "o.yaml", text);
    try {
      LoadOptions<OuterOptions>(dir / "o.yaml");
    } catch (const FormatError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string where = dir / "o.yaml";
  EXPECT_EQ(message_of("%YAML:1.\n -g\nm\n-"), where + ": not a YAML map of keys at the top");
  EXPECT_EQ(message_of("%YAML:1.0\n   uk2: -0.9531\n  p1: -0.0054\n"),
            where + ": not valid YAML (line 3: did not find expected <document start>)");
  EXPECT_EQ(message_of("%YAML:1.0\nouter: " + std::string(33000, '[') + std::string(33000, ']') + "\n"),
            where + ": YAML nested deeper than 64 levels");
  // A map to libyaml ("-U..." is a key), a list to OpenCV (fuzzer; OpenCV asserted on the first key lookup).
  EXPECT_EQ(message_of("%YAML:1.0\n-Utrinsics as pufx : ol\n"),
            where + ": not a YAML map of keys (as OpenCV reads it)");
  WriteFileAtomically(dir / "c.yaml", "%YAML:1.0\n-Utrinsics as pufx : ol\n");
  EXPECT_THROW(Camera::Read(dir / "c.yaml"), FormatError);
  // A matrix larger than its file could hold, which OpenCV would allocate before reading its data (fuzzer).
  EXPECT_EQ(message_of("%YAML:1.0\nm: !!opencv-matrix\n  rows: 100000\n  cols: 100000\n  dt: d\n  data: [1]\n")
                .rfind(where + ": line 2: a matrix of 10000000000 elements, more than the file's", 0),
            0u);
  EXPECT_NE(message_of("%YAML:1.0\nm: !!opencv-nd-matrix\n  sizes: [3000, 3000, 3000]\n  dt: d\n  data: [1]\n")
                .find("a matrix of 27000000000 elements"),
            std::string::npos);
  EXPECT_NE(message_of("%YAML:1.0\nm: !!opencv-matrix\n  rows: 2\n  cols: ~\n  dt: d\n  data: [1, 2]\n")
                .find("line 2: a matrix of a size that is not a whole number"),
            std::string::npos);
  // A second document (fuzzer: OpenCV never returned on this one).
  EXPECT_EQ(message_of("%YAML:1.0\n cx: A\n---\n-a: 5\n"), where + ": line 3: a second YAML document");
  // Cut short: refused at the end of the input.
  EXPECT_EQ(message_of("%YAML:1.0\nouter: {scale: [1").rfind(where + ": not valid YAML (line ", 0), 0u);
  // Without OpenCV's header line, OpenCV refuses the file: the message says what is missing.
  EXPECT_EQ(message_of("outer:\n  scale: [1, 2]\n"),
            where + ": OpenCV's YAML reader needs the header line %YAML:1.0 (then ---) first");
  // OpenCV's own header, with and without the document start, and a plain YAML file are taken.
  EXPECT_NO_THROW(CheckYamlText("%YAML:1.0\n---\na: 1\n", "x"));
  EXPECT_NO_THROW(CheckYamlText("%YAML:1.0\na: [1, 2]\nb: {c: 3}\n", "x"));
  EXPECT_NO_THROW(CheckYamlText("a: 1\n", "x"));
  for (const char* file : {"/vo/config/default.yaml", "/sim/config/default.yaml", "/infer/config/detector.yaml",
                           "/config/cameras/tum_fr1.yaml", "/models/default/model.yml"}) {
    EXPECT_NO_THROW(CheckYamlText(ReadFile(std::string(PDVO_SOURCE_DIR) + file), file)) << file;
  }
}

TEST(Options, MissingFileIsAnIoError) { EXPECT_THROW(LoadOptions<OuterOptions>("/nonexistent/o.yaml"), IoError); }

TEST(Options, OverridesSetNestedFields) {
  OuterOptions o;
  ApplyOverrides(o, {"inner.iterations=42", "enabled=false", "threshold=1e-3", "inner.weights=1,2,3"});
  EXPECT_EQ(o.inner.iterations, 42);
  EXPECT_FALSE(o.enabled);
  EXPECT_DOUBLE_EQ(o.threshold, 1e-3);
  EXPECT_EQ(o.inner.weights, (std::vector<double>{1, 2, 3}));
  ApplyOverrides(o, {"inner.weights=[4, 5.5]"});  // as the options files write lists
  EXPECT_EQ(o.inner.weights, (std::vector<double>{4, 5.5}));
  EXPECT_THROW(ApplyOverrides(o, {"inner.weights=[4, x]"}), InvalidArgument);
  EXPECT_THROW(ApplyOverrides(o, {"inner.weights=[4, 5"}), InvalidArgument);
  EXPECT_EQ(o.inner.weights, (std::vector<double>{4, 5.5}));  // a failed override changes nothing
  EXPECT_THROW(ApplyOverrides(o, {"inner.nope=1"}), InvalidArgument);
  EXPECT_THROW(ApplyOverrides(o, {"threshold=abc"}), InvalidArgument);
  EXPECT_THROW(ApplyOverrides(o, {"inner=3"}), InvalidArgument);
  EXPECT_THROW(ApplyOverrides(o, {"novalue"}), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
