/** \file
 * plume: PLUME_API marks the functions of the public interface. The library is compiled with
 * -fvisibility=hidden, so a function is exported from libplume.so only when its declaration in an
 * installed header carries PLUME_API; everything else (internal helpers that several files share)
 * stays inside the library, and the programs that use those helpers (the apps, the tests) link
 * libplume.a. tests/test_exports.c checks the exported set against the installed headers. */
#ifndef PLUME_EXPORT_H
#define PLUME_EXPORT_H

/** Marks a public function: default visibility (exported from libplume.so) with GCC and clang,
 * nothing elsewhere. */
#if defined(__GNUC__) || defined(__clang__)
#define PLUME_API __attribute__((visibility("default")))
#else
#define PLUME_API
#endif

#endif
