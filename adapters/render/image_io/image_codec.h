// The interface between image_file.cpp and the image codec module (libkmbvh_image_io.so,
// OpenImageIO), which image_file.cpp opens with dlopen on the first image it writes or
// reads: why a module, in CMakeLists.txt here. C functions and C types only, so that no
// C++ object is laid out differently on the two sides; errors come back as messages.
#pragma once

#include <stddef.h>
#include <stdint.h>

extern "C" {

// Writes `width` x `height` pixels of 3 channels, row by row from the top, to `path` in
// the format its extension names: `pixels` holds bytes when `is_float` is 0, 32-bit floats
// otherwise. Returns 0, or nonzero with a message in `error` (`error_size` bytes at most).
typedef int (*kmbvh_image_write_fn)(const char* path, uint32_t width, uint32_t height, int is_float,
                                    const void* pixels, char* error, size_t error_size);

// Where image `path` is read to: room for width * height * channels floats, or null (the
// read then fails). `user` is read's own argument.
typedef float* (*kmbvh_image_allocate_fn)(void* user, uint32_t width, uint32_t height, uint32_t channels);

// Reads `path` as 32-bit floats, all its channels, as stored (no transfer function undone).
// Returns 0, or nonzero with a message in `error`.
typedef int (*kmbvh_image_read_fn)(const char* path, kmbvh_image_allocate_fn allocate, void* user, char* error,
                                   size_t error_size);

}  // extern "C"

// The module's file and the names of its two functions.
#define KMBVH_IMAGE_IO_MODULE "libkmbvh_image_io.so"
#define KMBVH_IMAGE_WRITE_SYMBOL "kmbvh_image_write"
#define KMBVH_IMAGE_READ_SYMBOL "kmbvh_image_read"
