/// @file image_io.hpp
/// @brief The image I/O module: where sgbake's image reading and writing (loadImage, writeImage,
/// ImageFileWriter) comes from, and loading it ahead of time.
///
/// Image files are decoded and encoded by OpenImageIO inside a module, libsgbake_oiio.so,
/// installed beside libsgbake.so and loaded the first time an image is read or written. A
/// program that never reads or writes an image (tangents only, or the C ABI from Blender) never
/// loads OpenImageIO and the ~260 libraries it depends on on Debian; one that will can start
/// loading them on a thread of its own (~0.2–0.3 s of symbol resolution) while it does other
/// work, such as parsing a mesh.
#pragma once

#include <filesystem>

namespace sgbake {

/// @brief Starts loading the image I/O module on a background thread and returns at once. The
/// first image read or write then waits for it (and reports its failure, if any). Calling it
/// again, or after the module was loaded, does nothing. Thread-safe.
void preloadImageIo();

/// @brief Waits until a load preloadImageIo started has finished; does nothing when none was
/// started. A program that may exit soon after preloading (an early bad-input error) calls it
/// before exiting: a process that exits while another thread is inside `dlopen` runs its exit
/// handlers against half-initialized libraries. Thread-safe.
void finishImageIoPreload();

/// @brief The module's file: the environment variable `SGBAKE_IMAGE_IO_MODULE` when set and not
/// empty, else `libsgbake_oiio.so` in the directory libsgbake was loaded from.
std::filesystem::path imageIoModulePath();

}  // namespace sgbake
