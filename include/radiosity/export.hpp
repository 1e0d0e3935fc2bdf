// Symbol visibility for the radiosity library: the library is built with hidden visibility and
// exports exactly what is marked RADIOSITY_API.
#pragma once

#if defined(RADIOSITY_STATIC_DEFINE)
#define RADIOSITY_API
#elif defined(_WIN32)
#if defined(RADIOSITY_BUILDING)
#define RADIOSITY_API __declspec(dllexport)
#else
#define RADIOSITY_API __declspec(dllimport)
#endif
#else
#define RADIOSITY_API __attribute__((visibility("default")))
#endif
