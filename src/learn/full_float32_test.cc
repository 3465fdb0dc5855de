#include "learn/full_float32.h"

#include <ATen/Context.h>
#include <gtest/gtest.h>

namespace clothwind::learn {
namespace {

// Sets both switches and returns them to libtorch's defaults when the test ends, whatever it did.
class Tf32Switches : public ::testing::Test {
 protected:
  void Set(bool cudnn, bool cublas) {
    at::globalContext().setAllowTF32CuDNN(cudnn);
    at::globalContext().setAllowTF32CuBLAS(cublas);
  }
  bool Cudnn() const { return at::globalContext().allowTF32CuDNN(); }
  bool Cublas() const { return at::globalContext().allowTF32CuBLAS(); }
  void TearDown() override { Set(saved_cudnn_, saved_cublas_); }

 private:
  bool saved_cudnn_ = at::globalContext().allowTF32CuDNN(), saved_cublas_ = at::globalContext().allowTF32CuBLAS();
};

TEST_F(Tf32Switches, AScopeTurnsBothOffAndPutsEachBackAsItWas) {
  for (const bool cudnn : {true, false}) {
    for (const bool cublas : {true, false}) {
      Set(cudnn, cublas);
      {
        FullFloat32Scope scope;
        EXPECT_FALSE(Cudnn()) << cudnn << cublas;
        EXPECT_FALSE(Cublas()) << cudnn << cublas;
      }
      EXPECT_EQ(Cudnn(), cudnn) << "cuDNN's switch not put back";
      EXPECT_EQ(Cublas(), cublas) << "cuBLAS's switch not put back";
    }
  }
}

TEST_F(Tf32Switches, NestedScopesPutBackTheOuterState) {
  Set(true, true);
  {
    FullFloat32Scope outer;
    {
      FullFloat32Scope inner;
    }
    EXPECT_FALSE(Cudnn()) << "the inner scope's end turned TF32 back on inside the outer one";
  }
  EXPECT_TRUE(Cudnn());
  EXPECT_TRUE(Cublas());
}

TEST_F(Tf32Switches, UseFullFloat32OnCudaTurnsBothOff) {
  Set(true, true);
  UseFullFloat32OnCuda();
  EXPECT_FALSE(Cudnn());
  EXPECT_FALSE(Cublas());
}

}  // namespace
}  // namespace clothwind::learn
