// Removes the capture tests' scratch files when the test program ends.
#include "capture_test_support.h"

#include <cstdlib>

namespace arpipe::test {
namespace {

class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    if (std::getenv("ARPIPE_KEEP_SCRATCH") == nullptr) fs::remove_all(scratch_root());
  }
};

[[maybe_unused]] ::testing::Environment* const cleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

}  // namespace
}  // namespace arpipe::test
