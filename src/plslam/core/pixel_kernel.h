#pragma once
// PLSLAM_PIXEL_KERNEL marks a per-pixel loop that reads an image and writes a buffer of its own
// task (the 7x7 blur, the FAST ring tests, the ORB centroid and BRIEF tests). ThreadSanitizer
// leaves such loops uninstrumented, as it does OpenCV's own kernels: under TSan they took 55-60 %
// of a concurrent run (a shadow check per byte read), while the hand-off of their images and
// buffers between threads stays instrumented at the callers. Every other build, the address and
// undefined-behaviour sanitizers included, compiles them unchanged.
#if defined(__SANITIZE_THREAD__)
#define PLSLAM_PIXEL_KERNEL __attribute__((no_sanitize("thread")))
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define PLSLAM_PIXEL_KERNEL __attribute__((no_sanitize("thread")))
#endif
#endif
#ifndef PLSLAM_PIXEL_KERNEL
#define PLSLAM_PIXEL_KERNEL
#endif
