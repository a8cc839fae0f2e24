/*
** stb_write.c -- the one translation unit that compiles stb_image_write for
** the tests (test_image.c writes JPEGs with an EXIF segment spliced in).
** Its bit writer shifts a signed int past its range, which UBSan reports on
** every JPEG; the Makefile builds this file without -fsanitize=undefined, so
** `make asan` reports our code, not the library's.  Warnings are the
** library's business too: silenced here, and only here.
*/
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
