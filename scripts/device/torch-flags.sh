# Sourced by scripts/device-check and scripts/device-train: where libtorch is on this machine and
# how to compile against it. Needs $cxx (the C++ compiler), $out (where environment.txt goes) and
# $root (the checkout); sets abi, std, torch_dir (empty for Debian's), and the arrays torch_inc,
# torch_lib and launcher (arrays, so that paths with spaces stay one argument each).
#
# The Python package's copy of libtorch has CUDA where Debian's has not; without Python's PyTorch
# (as here) it falls back to Debian's, CPU only, which checks the scripts before a GPU is spent.
if torch_dir="$(python3 -c 'import os, torch; print(os.path.dirname(torch.__file__))' 2>/dev/null)"; then
  abi="$(python3 -c 'import torch; print(int(torch.compiled_with_cxx11_abi()))')"
  torch_inc=(-isystem "$torch_dir/include" -isystem "$torch_dir/include/torch/csrc/api/include")
  torch_lib=(-L"$torch_dir/lib" -Wl,-rpath,"$torch_dir/lib")
  # Linked even though no symbol of ours names them: libtorch_cuda registers the CUDA kernels
  # when it is loaded, and --as-needed would drop it.
  [ -f "$torch_dir/lib/libtorch_cuda.so" ] && torch_lib+=(-Wl,--no-as-needed -ltorch_cuda -lc10_cuda -Wl,--as-needed)
  python3 -c 'import torch; print("torch", torch.__version__, "cuda", torch.version.cuda, "device", torch.cuda.get_device_name(0) if torch.cuda.is_available() else None)' | tee "$out/environment.txt"
else
  abi=1
  torch_inc=(-isystem /usr/include/torch/csrc/api/include)
  torch_lib=()
  echo "torch: Debian's libtorch (CPU only)" | tee "$out/environment.txt"
fi
torch_lib+=(-ltorch -ltorch_cpu -lc10)
# Newer libtorch headers want C++20; take the newest standard the compiler offers of the two.
std=c++17
echo 'int main(){}' | "$cxx" -std=c++20 -x c++ - -o /dev/null 2>/dev/null && std=c++20
# ccache where there is one (here, not on the GPU machine), paths relative to the checkout
# ($root), so CI's clean clone reuses the objects the last check compiled: prefix compiles with
# "${launcher[@]}" (empty: the compiler alone).
launcher=()
# (an if, not &&: this file's last status is `source`'s, and the callers run under set -e)
if command -v ccache >/dev/null; then launcher=(env CCACHE_BASEDIR="$root" ccache); fi
