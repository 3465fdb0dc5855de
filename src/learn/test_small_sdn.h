// Test helper: the shipped SDN's shape at a smaller input, for tests that save, load or run one.
#ifndef CLOTHWIND_LEARN_TEST_SMALL_SDN_H_
#define CLOTHWIND_LEARN_TEST_SMALL_SDN_H_

#include "learn/model_config.h"

namespace clothwind::learn {

// Returns an SDN of grey 30-frame clips of 32 px, k = 3 with phase steps, width 8.
inline ModelConfig SmallSdn() {
  ModelConfig config;
  config.arch = "sdn";
  config.frames = 30;
  config.k = 3;
  config.phase_steps = true;
  config.width = 8;
  config.input_size = 32;
  return config;
}

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TEST_SMALL_SDN_H_
