// The sample loop as its callers see it and as the library built it. The inline accessors of
// SampleLoop (mode(), health(), ...) are compiled into the caller; the members are written by
// sample_loop.cpp in libgfins_app. An object of that library compiled against older headers (an
// incremental build that missed an edit) made the loop report mode 0 on armhf although it
// navigated: sizeof(SampleLoop) agreed (83728 both ways, a grown member went into the 16-byte
// tail padding) but the members after it moved (docs/ci.md, "armhf: ... reported mode 0").
#include <gtest/gtest.h>

#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

TEST(SampleLoopLayout, TheLibraryWasBuiltAgainstTheHeadersItsCallersSee) {
  // The oracle is the compiler's layout of this translation unit; a mismatch means a stale
  // libgfins_app object: rebuild it.
  EXPECT_EQ(SampleLoop::built_layout_signature(), SampleLoop::layout_signature())
      << "sample_loop.cpp was compiled against other headers than this test";
}

TEST(SampleLoopLayout, TheModeReadInlineIsTheOneTheLoopWrote) {
  // Given the simulated board at rest (scenario "rest": 1000 alignment samples, docs/firmware.md)
  SimRig rig("rest", 0.1);
  // Before configure() the loop is starting up; configure() (out of line) starts alignment.
  EXPECT_EQ(rig.loop->mode(), Mode::kStartup);
  rig.configure();
  EXPECT_EQ(rig.loop->mode(), Mode::kAligning);
  // After one sample the epoch the loop published (written by sample_loop.cpp, recorded by the
  // sink) and the inline accessor agree.
  rig.run_cycles(1);
  ASSERT_FALSE(rig.recording->epochs().empty());
  EXPECT_EQ(rig.recording->epochs().back().mode, rig.loop->mode());
  EXPECT_EQ(rig.loop->mode(), Mode::kAligning);
}

}  // namespace
}  // namespace gfins::app
