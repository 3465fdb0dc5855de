// Full float32 in CUDA's convolutions and matrix products. libtorch allows TF32 in cuDNN's
// convolutions by default, which rounds their inputs to 10 mantissa bits (~1e-3 relative): a
// network run so is another network than the float32 one the CPU runs, the node serves and the
// figures were measured with. The switches are process-wide (libtorch has none per module); on a
// CPU they are flags that nothing reads.
#ifndef CLOTHWIND_LEARN_FULL_FLOAT32_H_
#define CLOTHWIND_LEARN_FULL_FLOAT32_H_

namespace clothwind::learn {

// Turns TF32 off for the rest of the process (cuDNN convolutions and cuBLAS products).
void UseFullFloat32OnCuda();

// Turns TF32 off while it lives and puts both switches back as they were when it goes. Training
// keeps libtorch's TF32 for its steps (faster, and the noise of a step is larger), and validates
// under one: the epoch kept as model.pt is picked by the float32 network eval and the node run.
class FullFloat32Scope {
 public:
  FullFloat32Scope();
  ~FullFloat32Scope();
  FullFloat32Scope(const FullFloat32Scope&) = delete;
  FullFloat32Scope& operator=(const FullFloat32Scope&) = delete;

 private:
  bool cudnn_tf32_, cublas_tf32_;  // as they were
};

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FULL_FLOAT32_H_
