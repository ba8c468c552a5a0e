#pragma once
// Block-level building blocks of the CUDA backend: one thread block runs the jet forward pass,
// the losses and the reverse pass of a *chunk* of points entirely in shared memory. Every CUDA
// entry point (the twins in cuda/mlp_jet_forward.cu, mlp_jet_backward.cu, loss_step.cu, the
// fused epoch kernel in train/cuda_backend.cu) is made of these functions, except
// mlp_loss_grad of Net-3, which runs on the tensor-core warp path of cuda/mma_jet.cuh (it
// shares the per-point sigmoid jets of cuda/sigmoid_jet.cuh and losses of cuda/loss_jets.cuh).
// This header gathers the parts, one concept per file:
//   cuda/jet_shape.cuh       the network's shape, loss configuration, chunk layout in shared memory
//   cuda/block_products.cuh  the tiled products, the weight gradient in slices, fixed-order sums
//   cuda/sigmoid_jet.cuh     the sigmoid jet of one neuron at one point and its reverse
//   cuda/chunk_jet.cuh       the forward and reverse pass of a chunk, layer by layer
//   cuda/loss_jets.cuh       the losses and their adjoints (one point, a chunk)
//   cuda/batch_tasks.cuh     a batch as chunk tasks: where its points come from, the task loop
//
// The math is the CPU's (cpu/mlp_jet.hpp, cpu/sigmoid_jet.hpp, cpu/losses.cpp); so is the
// layout of a jet inside a chunk of np points: a layer's jet is [n, S] with channel c of point
// p in column c*np + p (the CPU's [n, C*B] with B = np), S >= C*np the row stride. S is kept
// at 4 mod 32 floats so that the float4 loads of the gradient sums, whose lanes walk down the
// rows, hit distinct banks.
//
// Determinism: every sum (a matrix product's inner sum, a weight gradient over a chunk's
// columns, the loss terms over its points) is computed by one thread in a fixed order, or by a
// fixed shuffle tree; a chunk's gradient is added into the block's gradient by the one thread
// that owns that parameter, chunk after chunk. No atomics anywhere.
#include "cuda/batch_tasks.cuh"
#include "cuda/block_products.cuh"
#include "cuda/chunk_jet.cuh"
#include "cuda/jet_shape.cuh"
#include "cuda/loss_jets.cuh"
#include "cuda/sigmoid_jet.cuh"
