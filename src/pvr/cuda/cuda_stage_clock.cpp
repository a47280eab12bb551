#include "pvr/cuda/cuda_stage_clock.h"

namespace pvr::cuda {

void CudaStageClock::newFrame() {
  for (Slot& s : slots_) s.used = 0, s.added = 0;
}

void CudaStageClock::begin(Stage stage, int eye) {
  nvtxRangePushA(stageName(stage));
  Slot& s = slots_[slot(stage, eye)];
  if (s.used == int(s.runs.size())) s.runs.push_back(std::make_unique<EventTimer>());
  s.runs[s.used]->start(stream_);
}

void CudaStageClock::end(Stage stage, int eye) {
  Slot& s = slots_[slot(stage, eye)];
  s.runs[s.used++]->stopNoThrow(stream_);
  nvtxRangePop();
}

double CudaStageClock::ms(Stage stage, int eye) {
  const Slot& s = slots_[slot(stage, eye)];
  double total = s.added;
  for (int r = 0; r < s.used; ++r) total += s.runs[r]->ms();
  return total;
}

}  // namespace pvr::cuda
