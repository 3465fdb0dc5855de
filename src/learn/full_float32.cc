#include "learn/full_float32.h"

#include <ATen/Context.h>

namespace clothwind::learn {

void UseFullFloat32OnCuda() {
  at::globalContext().setAllowTF32CuDNN(false);
  at::globalContext().setAllowTF32CuBLAS(false);
}

FullFloat32Scope::FullFloat32Scope()
    : cudnn_tf32_(at::globalContext().allowTF32CuDNN()), cublas_tf32_(at::globalContext().allowTF32CuBLAS()) {
  UseFullFloat32OnCuda();
}

FullFloat32Scope::~FullFloat32Scope() {
  at::globalContext().setAllowTF32CuDNN(cudnn_tf32_);
  at::globalContext().setAllowTF32CuBLAS(cublas_tf32_);
}

}  // namespace clothwind::learn
