/*
** stb_image_impl.h -- stb_image compiled into image.c, its one user
** (libstb-dev ships it as a header only), every function static: a
** program that embeds liblinewise.a and has its own stb_image (most GUI
** programs do) neither met 31 duplicate symbols at its link nor, linked the
** other way round, had its stb_image read linewise's pictures (its
** stbi_set_flip_vertically_on_load turned them upside down).  Only PNG, JPEG, GIF and BMP are
** built (image.c reads PGM/PPM itself), from memory only (image.c reads files itself so that it can
** say why a file could not be read), with the decoder's user-facing
** failure messages.  Warnings are the library's business: silenced here,
** and only here.
*/
#ifndef LINEWISE_STB_IMAGE_IMPL_H
#define LINEWISE_STB_IMAGE_IMPL_H

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_BMP
#define STBI_ONLY_GIF

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#endif
