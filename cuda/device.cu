// The device and its memory (declared in cuda/api.hpp): which GPUs there are, the error when
// there is none, DeviceVec (an owned device array), EventTimer, synchronize.
#include <cuda_runtime.h>

#include <string>
#include <vector>

#include "cuda/api.hpp"
#include "cuda/check.cuh"

namespace yarnhom::cuda {

int device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return 0;
  }
  return n;
}

std::string device_description() {
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();
    return std::string("no usable CUDA device (") + cudaGetErrorString(e) + ")";
  }
  if (n == 0) return "no CUDA device";
  int dev = 0;
  cudaGetDevice(&dev);
  cudaDeviceProp p{};
  cudaGetDeviceProperties(&p, dev);
  return std::string(p.name) + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
         std::to_string(p.multiProcessorCount) + " SMs)";
}

void require_device() {
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();
    throw CudaError(std::string("the CUDA backend needs a GPU, and none is usable: ") + cudaGetErrorString(e));
  }
  if (n == 0) throw CudaError("the CUDA backend needs a GPU, and this machine has none");
}

void synchronize() { check(cudaDeviceSynchronize(), "cudaDeviceSynchronize"); }

// ---- DeviceVec ----
template <class T>
void DeviceVec<T>::resize(size_t n) {
  if (n == n_) return;
  release();
  if (n == 0) return;
  void* p = nullptr;
  check(cudaMalloc(&p, n * sizeof(T)), "cudaMalloc of " + std::to_string(n * sizeof(T)) + " bytes");
  p_ = static_cast<T*>(p);
  n_ = n;
}
template <class T>
void DeviceVec<T>::upload(const std::vector<T>& h) {
  resize(h.size());
  if (n_) check(cudaMemcpy(p_, h.data(), n_ * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to the device");
}
template <class T>
std::vector<T> DeviceVec<T>::download() const {
  std::vector<T> h(n_);
  if (n_) check(cudaMemcpy(h.data(), p_, n_ * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy from the device");
  return h;
}
template <class T>
void DeviceVec<T>::fill_zero() {
  if (n_) check(cudaMemset(p_, 0, n_ * sizeof(T)), "cudaMemset");
}
template <class T>
void DeviceVec<T>::release() {
  if (p_) cudaFree(p_);
  p_ = nullptr;
  n_ = 0;
}
template class DeviceVec<float>;
template class DeviceVec<int>;

// ---- EventTimer ----
EventTimer::EventTimer() {
  cudaEvent_t a, b;
  check(cudaEventCreate(&a), "cudaEventCreate");
  check(cudaEventCreate(&b), "cudaEventCreate");
  a_ = a, b_ = b;
}
EventTimer::~EventTimer() {
  cudaEventDestroy(static_cast<cudaEvent_t>(a_));
  cudaEventDestroy(static_cast<cudaEvent_t>(b_));
}
void EventTimer::start() { check(cudaEventRecord(static_cast<cudaEvent_t>(a_)), "cudaEventRecord"); }
double EventTimer::stop_ms() {
  check(cudaEventRecord(static_cast<cudaEvent_t>(b_)), "cudaEventRecord");
  check(cudaEventSynchronize(static_cast<cudaEvent_t>(b_)), "cudaEventSynchronize");
  float ms = 0;
  check(cudaEventElapsedTime(&ms, static_cast<cudaEvent_t>(a_), static_cast<cudaEvent_t>(b_)), "cudaEventElapsedTime");
  return ms;
}

}  // namespace yarnhom::cuda
