// Silences the warnings of a third-party header compiled into a file of ours (stb's single-file
// implementations), which -Werror would otherwise turn into errors we cannot fix:
//
//   RADIOSITY_THIRD_PARTY_BEGIN
//   #include <stb_image.h>
//   RADIOSITY_THIRD_PARTY_END
#pragma once

#define RADIOSITY_THIRD_PARTY_BEGIN                                  \
  _Pragma("GCC diagnostic push")                                     \
  _Pragma("GCC diagnostic ignored \"-Wall\"")                        \
  _Pragma("GCC diagnostic ignored \"-Wextra\"")                      \
  _Pragma("GCC diagnostic ignored \"-Wpedantic\"")                   \
  _Pragma("GCC diagnostic ignored \"-Wshadow\"")                     \
  _Pragma("GCC diagnostic ignored \"-Wmissing-field-initializers\"") \
  _Pragma("GCC diagnostic ignored \"-Wsign-compare\"")               \
  _Pragma("GCC diagnostic ignored \"-Wunused-parameter\"")           \
  _Pragma("GCC diagnostic ignored \"-Wunused-function\"")            \
  _Pragma("GCC diagnostic ignored \"-Wimplicit-fallthrough\"")       \
  _Pragma("GCC diagnostic ignored \"-Wdouble-promotion\"")

#define RADIOSITY_THIRD_PARTY_END _Pragma("GCC diagnostic pop")
