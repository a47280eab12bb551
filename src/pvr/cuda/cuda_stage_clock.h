#pragma once
// Stage times on the GPU: a pair of CUDA events around each run of a stage on the backend's
// stream, read once the frame is finished; each stage is also an NVTX range, so nsys and ncu show
// the kernels under their stage's name.
#include <cuda_runtime.h>

#include <array>
#include <memory>
#include <vector>

#include "pvr/cuda/cuda_util.cuh"
#include "pvr/pipeline/stage_clock.h"

namespace pvr::cuda {

class CudaStageClock : public StageClock {
 public:
  explicit CudaStageClock(cudaStream_t stream) : stream_(stream) {}
  void newFrame() override;
  void begin(Stage stage, int eye) override;
  void end(Stage stage, int eye) override;
  double ms(Stage stage, int eye) override;  ///< waits for the stage's last event
  void add(Stage stage, int eye, double ms) override { slots_[slot(stage, eye)].added += ms; }

 private:
  struct Slot {
    std::vector<std::unique_ptr<EventTimer>> runs;  ///< grow-only, reused across frames
    int used = 0;
    double added = 0;  ///< times measured elsewhere (Vulkan timestamps)
  };
  static int slot(Stage stage, int eye) { return int(stage) * 3 + eye + 1; }
  cudaStream_t stream_;
  std::array<Slot, int(Stage::Count) * 3> slots_;
};

}  // namespace pvr::cuda
