/* scene.c -- building the scene from parameters (scene.h). */
#include "linewise/scene.h"

#include <gsl/gsl_math.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/fidelity.h"
#include "linewise/fieldfile.h"
#include "linewise/imagefield.h"
#include "linewise/number.h"
#include "linewise/sdt.h"
#include "linewise/state.h"

#define DEG (M_PI / 180.0)

/* Every message about a key reads "file:line: key 'section.key': ...". */
static lw_status bad_key(const lw_params *p, const char *section, const char *key, lw_status code,
                         lw_error *err, const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static lw_status bad_key(const lw_params *p, const char *section, const char *key, lw_status code,
                         lw_error *err, const char *fmt, ...)
{
  if (!err) return code;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->msg, sizeof err->msg, fmt, ap);
  va_end(ap);
  err->code = code;
  return lw_params_blame(p, section, key, err);
}

/* A term's own nodes q: n of them where the term is on and n is set (the
** key energy.key), else the scene's. */
static lw_status term_nodes(const lw_params *p, const lw_scene *sc, int on, const char *key, int n, lw_quad *q,
                            lw_error *err)
{
  *q = sc->quad;
  if (!on || !n || n == sc->quad.n) return LW_OK;
  if (n < LW_QUAD_MIN)
    return bad_key(p, "energy", key, LW_EINPUT, err, "expected 0 or %d to %d nodes, got %d", LW_QUAD_MIN, LW_QUAD_MAX,
                   n);
  return lw_quad_init(q, n, err);
}

double lw_pair_near_least(const lw_quad *q)
{
  double w = 0.0;
  for (int i = 0; i < q->n; i++) w = fmax(w, q->w[i]);
  return M_SQRT2 * q->spacing / w;
}

/* The margin box: the page inset by `margin`, which frames the rect and
** circle boundaries and holds the picture. */
static lw_status margin_ok(const lw_params *p, lw_error *err)
{
  if (2 * p->margin >= p->width || 2 * p->margin >= p->height)
    return bad_key(p, "scene", "margin", LW_EINPUT, err, "expected less than half the page (%g x %g mm), got %g",
                   p->width, p->height, p->margin);
  return LW_OK;
}

/* The fewest pixels a scaled W x H picture's short side may keep: 4, or
** the picture's own where it has fewer.  Scaled to fewer, a picture loses
** its shape to the rounding (a 20000 x 20 panorama at 1 x 1 filled a square
** page): a budget or width that asks for that is refused. */
static double least_side(int W, int H) { return fmin(4.0, fmin(W, H)); }

/* Loads the picture of section.key (scene.image, scene.mask_image,
** output.fidelity_reference) at path, relative to the scene file, and fits
** it into the margin box; which: its luma, or a mask's inside (image.h). */
/* A file's path as a key gives it, relative to the scene file, into full
** (2 * LW_PATH_MAX + 2 bytes). */
static void scene_relative(const lw_params *p, const char *path, char *full)
{
  char dir[LW_PATH_MAX];
  lw_path_dir(dir, sizeof dir, p->file);
  lw_path_join(full, 2 * LW_PATH_MAX + 2, dir, path);
}

static lw_image *load_picture(lw_scene *sc, const lw_params *p, const char *section, const char *key,
                              const char *path, lw_image_channel which, lw_image_place *pl, lw_error *err)
{
  char full[2 * LW_PATH_MAX + 2];
  scene_relative(p, path, full);
  lw_image_info info;
  lw_error e2;
  lw_image *img = lw_image_load_channel(full, p->image_max_pixels, which, &info, &e2);
  if (!img) {
    bad_key(p, section, key, e2.code, err, "%s", e2.msg);
    return NULL;
  }
  const double all = (double)info.width * info.height, side = fmin(info.width, info.height);
  if (all > p->image_max_pixels && side * sqrt(p->image_max_pixels / all) < least_side(info.width, info.height)) {
    const double m = least_side(info.width, info.height);
    bad_key(p, "scene", "image_max_pixels", LW_EINPUT, err, "%s: a %d x %d picture within %.0f pixels keeps %.2f "
            "pixels across, too few to keep its shape: expected at least %.0f pixels (%.0f across)", full, info.width,
            info.height, p->image_max_pixels, side * sqrt(p->image_max_pixels / all), ceil(all * m * m / (side * side)),
            m);
    lw_image_free(img);
    return NULL;
  }
  if (img->width != info.width || img->height != info.height) {
    size_t used = strlen(sc->note);
    snprintf(sc->note + used, sizeof sc->note - used,
             "%s%s: %d x %d pixels is more than scene.image_max_pixels (%.0f): downsampled to %d x %d",
             used ? "\n" : "", full, info.width, info.height, p->image_max_pixels, img->width, img->height);
  }
  *pl = lw_image_fit(img->width, img->height, p->margin, p->margin, p->width - p->margin,
                     p->height - p->margin);
  return img;
}

/* A picture the drawing's score (fidelity.h) cannot render is refused
** before the run, not after it (a 100000 x 1 strip annealed, then failed). */
static lw_status scored_side_ok(const lw_params *p, const char *section, const char *key, const lw_image *img,
                                lw_error *err)
{
  if (img->width <= LW_FIDELITY_SIDE_MAX && img->height <= LW_FIDELITY_SIDE_MAX) return LW_OK;
  return bad_key(p, section, key, LW_EINPUT, err, "%d x %d pixels: the drawing is scored on the picture's pixels, "
                 "and cairo renders at most %d a side; expected a picture cropped or scaled to fit (or "
                 "scene.image_width)", img->width, img->height, LW_FIDELITY_SIDE_MAX);
}

/* Whether a run begun before scene key `key` came has no line for it in its
** scene.ini: it resumes with the key's old behaviour, as it ran (a scene.ini
** written by hand beside a state takes the default).  The keys of
** 2026-12-05 and 06: field_core, image_levels_alpha, image_levels_flat,
** potential_paper, potential_fine, layers.share_width. */
static int before_key_of(const lw_params *p, const char *section, const char *key)
{
  return p->run_written && !lw_params_line(p, section, key);
}

static int before_key(const lw_params *p, const char *key)
{
  return before_key_of(p, "scene", key);
}

/* The potential of picture img (the scene's, or a layer's target) placed as
** the scene's picture, with the blur's paper and the wide pixels' finer grid
** where the run's keys ask for them. */
static lw_grid2d *image_potential(const lw_scene *sc, const lw_image *img, const lw_params *p, lw_error *err)
{
  return lw_imagefield_potential(img, &sc->image_place, p->potential_power, p->potential_blur / sc->image_place.pixel,
                                 p->potential_paper && !before_key(p, "potential_paper"),
                                 p->potential_fine && !before_key(p, "potential_fine"), err);
}

/* A picture dark nearly all over asks for the densest lines nearly
** everywhere: an even hatch, with only its lights as gaps (skimage's rocket
** at night, 60 % of it 80 % dark; the Hubble deep field, 95 %), which the
** scores do not show (the best SSIM of 11 photographs).  Said before the run,
** with the keys that lighten it: counted over the picture's pixels inside
** the frame (a mask's dark outside is never drawn), on a grid of at most
** about 250,000 of them, and only where the tone curve makes the target (a
** colour separation takes the channels without it).  A transparent pixel
** counts as the white paper it shows (its tone is composited over white):
** a black logo on transparent paper, a fifth of the picture, was said dark
** all over, and the advice (invert) left nothing to draw. */
#define DARK_TONE 0.2  /* 80 % dark or darker */
#define DARK_SHARE 0.5 /* of the picture's pixels in the frame, and of all of them */
#define LIGHT_SHARE 0.25 /* of all of them 80 % light or lighter: paper around a graphic */
static void dark_note(lw_scene *sc, const lw_params *p)
{
  if (!sc->on[LW_TERM_TONE] && !(sc->on[LW_TERM_POTENTIAL] && p->potential == LW_POT_IMAGE)) return;
  if (p->ly_source != LW_LSRC_TONE) return;
  const lw_image *im = sc->image;
  const lw_image_place *pl = &sc->image_place;
  const int step = (int)ceil(sqrt((double)im->width * im->height / 250000.0));
  /* dark inside the frame, and in the picture as a whole: lettering masked
  ** by its own glyphs is all dark inside and wants just that */
  size_t dark = 0, seen = 0, dark_all = 0, seen_all = 0, light_all = 0;
  for (int j = 0; j < im->height; j += step)
    for (int i = 0; i < im->width; i += step) {
      const size_t k = (size_t)j * (size_t)im->width + (size_t)i;
      seen_all++;
      dark_all += im->tone[k] <= DARK_TONE;
      light_all += im->tone[k] >= 1.0 - DARK_TONE;
      if (!lw_boundary_inside(&sc->boundary, pl->x0 + (i + 0.5) * pl->pixel, pl->y0 + (j + 0.5) * pl->pixel))
        continue;
      seen++;
      dark += im->tone[k] <= DARK_TONE;
    }
  size_t used = strlen(sc->note);
  /* a picture transparent everywhere is white paper: the empty drawing that
  ** follows blamed the price of line (an exporter's alpha of 0); every pixel
  ** is asked, not the grid's (thin lines between its rows were missed) */
  int clear = im->alpha != NULL;
  for (size_t k = 0, n = (size_t)im->width * (size_t)im->height; clear && k < n; k++)
    clear = im->alpha[k] < 0.5f / 255.0f;
  if (clear) {
    snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image: the picture is transparent everywhere (its "
             "alpha is 0 at every pixel), so it is all white paper and asks for no line; a picture saved with an "
             "alpha of 0 by mistake draws once saved without its alpha channel", used ? "\n" : "");
    return;
  }
  if (!seen || (double)dark <= DARK_SHARE * (double)seen || (double)dark_all <= DARK_SHARE * (double)seen_all) return;
  /* (a black disc on white, half the picture each: the note told its maker
  ** to invert it, which turns the white surround dark) */
  const int paper = (double)light_all >= LIGHT_SHARE * (double)seen_all;
  snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image: %.0f %% of the picture is %.0f %% dark or darker "
           "after its tone curve, so the lines there can only hatch evenly at their densest and little of the picture "
           "shows; scene.image_gamma below 1 lightens its mid-tones, %s (docs/IMAGES.md, \"What the preset does not "
           "draw\")", used ? "\n" : "", 100.0 * (double)dark / (double)seen, 100.0 * (1.0 - DARK_TONE),
           p->image_invert ? "scene.image_invert = 0 draws its dark parts (the inversion made it dark)"
           : paper         ? "while a graphic of flat dark on white paper draws as it is (inverted, its paper would "
                             "turn dark)"
                           : "scene.image_invert = 1 draws its light parts");
}

/* A picture of another shape than the frame keeps its shape inside it, so a
** panorama on a page becomes a strip: 4000 x 3 pixels on A6 was 128 x 0.1
** mm, drew no line, and was blamed on a pale picture; 4000 x 30 drew 7
** strokes in a row and scored SSIM 0.79.  Said before the run where the
** placed picture is narrower than two segments (about the least room a
** curve needs to bend in).  A mask picture's strip is the most room its
** inside has (its empty drawing was blamed on the price of line). */
static void thin_note(lw_scene *sc, const lw_params *p, const char *key, const lw_image *img,
                      const lw_image_place *pl)
{
  const double w = img->width * pl->pixel, h = img->height * pl->pixel;
  if (fmin(w, h) >= 2.0 * p->segment_length) return;
  size_t used = strlen(sc->note);
  snprintf(sc->note + used, sizeof sc->note - used, "%sscene.%s: the %d x %d picture keeps its shape, so it lies on "
           "the page as %.3g x %.3g mm, narrower than two segments (init.segment_length %g mm): few lines or none fit "
           "there; a crop of the picture to a less narrow shape gives it room, and so do shorter segments",
           used ? "\n" : "", key, img->width, img->height, w, h, p->segment_length);
}

/* A picture that no term of the energy reads: it places the splines' start
** and scores the drawing, but the annealing does not follow it (a scene of
** "[scene] image = photo.jpg" alone drew random lines without a word;
** layers read it through the same terms, each its own target). */
static void unread_picture_note(lw_scene *sc, const lw_params *p)
{
  const int read = sc->on[LW_TERM_TONE] || (sc->on[LW_TERM_POTENTIAL] && p->potential == LW_POT_IMAGE) ||
                   (sc->on[LW_TERM_FIELD] && (p->field == LW_FLD_ETF || p->field == LW_FLD_GRADIENT)) ||
                   (p->boundary == LW_BND_MASK && p->mask == LW_MASK_ALPHA);
  if (read) return;
  size_t used = strlen(sc->note);
  snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image: no term of the energy reads the picture, so the "
           "drawing does not follow it (only the splines' first places do); scene.preset = photo draws a picture, as "
           "do energy.tone, scene.potential = image or scene.field = etf (docs/IMAGES.md)", used ? "\n" : "");
}

/* The picture pipeline after loading: resize, blur, flattening, levels, tone curve. */
static lw_status build_image(lw_scene *sc, const lw_params *p, lw_error *err)
{
  lw_status st = margin_ok(p, err);
  if (st) return st;
  /* a mask's picture that cannot be read is said before the picture's
  ** pipeline, not after it (25 s under valgrind; seconds on a photograph) */
  if (p->boundary == LW_BND_MASK && p->mask == LW_MASK_IMAGE && p->mask_image[0]) {
    char full[2 * LW_PATH_MAX + 2];
    scene_relative(p, p->mask_image, full);
    lw_image_info info;
    lw_error e2;
    if (lw_image_probe(full, &info, &e2)) return bad_key(p, "scene", "mask_image", e2.code, err, "%s", e2.msg);
  }
  sc->image = load_picture(sc, p, "scene", "image", p->image, LW_IMAGE_LUMA, &sc->image_place, err);
  if (!sc->image) return err->code;
  if (p->image_width > 0 && p->image_width != sc->image->width) {
    double h = (double)sc->image->height * p->image_width / sc->image->width;
    int hh = h < 1 ? 1 : (int)lround(h);
    const int W = sc->image->width, H = sc->image->height;
    const double m = least_side(W, H);
    if (fmin(p->image_width, h) < m)
      return bad_key(p, "scene", "image_width", LW_EINPUT, err, "%d pixels wide, the %d x %d picture keeps %.2f "
                     "pixels across, too few to keep its shape: expected at least %.0f", p->image_width, W, H,
                     fmin(p->image_width, h), ceil(H < W ? m * W / H : m));
    if ((double)p->image_width * hh > p->image_max_pixels)
      return bad_key(p, "scene", "image_width", LW_EINPUT, err,
                     "%d x %d pixels is more than scene.image_max_pixels (%.0f)", p->image_width, hh,
                     p->image_max_pixels);
    lw_image *r = lw_image_resize(sc->image, p->image_width, hh, err);
    if (!r) return err->code;
    lw_image_free(sc->image);
    sc->image = r;
    sc->image_place = lw_image_fit(r->width, r->height, p->margin, p->margin, p->width - p->margin,
                                   p->height - p->margin);
  }
  if ((st = scored_side_ok(p, "scene", p->image_width > 0 ? "image_width" : "image", sc->image, err))) return st;
  if (p->crop) { /* (params.c: the strokes are cut to the picture's rectangle) */
    const lw_image_place *pl = &sc->image_place;
    const double box[4] = {pl->x0, pl->y0, pl->x0 + sc->image->width * pl->pixel,
                           pl->y0 + sc->image->height * pl->pixel};
    char what[160];
    snprintf(what, sizeof what, "the picture's %.4g x %.4g mm rectangle from (%.4g, %.4g) mm, to which plot.crop cuts "
             "the strokes", box[2] - box[0], box[3] - box[1], box[0], box[1]);
    if ((st = lw_params_bed_check(p, box, what, err))) return st;
  }
  if ((st = lw_image_blur(sc->image, p->image_blur / sc->image_place.pixel, err))) return st;
  if (p->image_flatten > 0) {
    double lo, hi;
    if ((st = lw_image_flatten(sc->image, p->image_flatten / sc->image_place.pixel, &lo, &hi, err))) return st;
    size_t used = strlen(sc->note);
    snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image_flatten: paper tones %.3f to %.3f divided out",
             used ? "\n" : "", lo, hi);
  }
  /* The levels and the tone curve take the picture under its transparency
  ** (image.h).  A blur spreads the picture's edge onto its transparent side,
  ** so they take the alpha blurred alike: with the sharp one, the spread
  ** edge was left out of the curve (an inverted picture got a ring of ink). */
  const int curve = p->image_invert || p->image_gamma != 1.0 || p->image_contrast != 1.0;
  const size_t npx = (size_t)sc->image->width * (size_t)sc->image->height;
  float *cover = NULL;
  /* (a run begun before 2026-12-06, whose scene.ini has no line for the
  ** key, stretched the composite: potential_paper below) */
  const int levels_under =
      p->image_levels_alpha && !before_key(p, "image_levels_alpha");
  if (sc->image->alpha && (curve || (p->image_levels > 0 && levels_under)) && p->image_blur > 0) {
    if (!(cover = malloc(npx * sizeof *cover)))
      return lw_error_set(err, LW_ENOMEM, "out of memory for the picture's transparency");
    memcpy(cover, sc->image->alpha, npx * sizeof *cover);
    if ((st = lw_image_blur_plane(cover, sc->image->width, sc->image->height,
                                  p->image_blur / sc->image_place.pixel, err))) {
      free(cover);
      return st;
    }
  }
  if (p->image_levels > 0) {
    double lo, hi;
    int kept;
    const float *under = levels_under ? (cover ? cover : sc->image->alpha) : NULL;
    /* (a run begun before the key: the clip's bin alone) */
    const int flat = before_key(p, "image_levels_flat") ? 0 : p->image_levels_flat;
    if ((st = lw_image_levels(sc->image, under, p->image_levels, flat, &lo, &hi, &kept, err))) {
      free(cover);
      return st;
    }
    size_t used = strlen(sc->note);
    /* a light picture's darkest is a light grey, which the stretch makes
    ** black: a pale sky drew at the darkest density (docs/IMAGES.md);
    ** inverted after (the tone curve), it makes it paper; a hazy one, no
    ** white in it either, is what the stretch is for */
    if (lo > 0.0 || hi < 1.0)
      snprintf(sc->note + used, sizeof sc->note - used,
               "%sscene.image_levels: tones %.3f to %.3f stretched to 0 to 1%s", used ? "\n" : "", lo, hi,
               lo >= LW_IMAGE_LEVELS_LIGHT && hi >= LW_IMAGE_LEVELS_PAPER && !p->image_invert
                   ? " (its darkest, a light grey, now draws as black: scene.image_levels = 0 keeps a light picture "
                     "light)"
                   : "");
    else if (!kept) /* a plateau of paper or of black at an end keeps its end */
      snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image_levels: the tones left as they are",
               used ? "\n" : "");
    else /* (a dim photograph saved as a GIF, its sky one colour of 11 %, kept its tones unsaid why) */
      snprintf(sc->note + used, sizeof sc->note - used, "%sscene.image_levels: the tones left as they are: %s one "
               "flat colour of many pixels, as a graphic's (a photograph saved in few colours, a GIF, looks so "
               "too: there scene.image_gamma and image_contrast set its tones by hand)", used ? "\n" : "",
               kept == 3 ? "its darkest and its lightest tone are each" : kept == 2 ? "its lightest tone is"
                                                                                   : "its darkest tone is");
  }
  lw_image_tone_curve(sc->image, cover ? cover : sc->image->alpha, p->image_gamma, p->image_contrast,
                      p->image_invert);
  free(cover);
  return LW_OK;
}

/* boundary = mask: inside is alpha >= 1/2 of the picture (mask = alpha) or
** tone < 1/2 of the mask picture composited over white (mask = image). */
static lw_status build_mask(lw_scene *sc, const lw_params *p, lw_error *err)
{
  if (p->mask == LW_MASK_NONE)
    return bad_key(p, "scene", "boundary", LW_EINPUT, err, "'mask' needs scene.mask = alpha or image");
  const lw_image *img = sc->image;
  lw_image_place pl = sc->image_place;
  lw_image *own = NULL;
  if (p->mask == LW_MASK_ALPHA) {
    if (!img) return bad_key(p, "scene", "mask", LW_EINPUT, err, "'alpha' needs scene.image");
    if (!img->alpha)
      return bad_key(p, "scene", "mask", LW_EINPUT, err, "'alpha': %s has no alpha channel", p->image);
  } else {
    if (!p->mask_image[0]) return bad_key(p, "scene", "mask", LW_EINPUT, err, "'image' needs scene.mask_image");
    lw_status st = margin_ok(p, err);
    if (st) return st;
    img = own = load_picture(sc, p, "scene", "mask_image", p->mask_image, LW_IMAGE_MASK, &pl, err);
    if (!own) return err->code;
    thin_note(sc, p, "mask_image", img, &pl);
  }
  size_t n = (size_t)img->width * (size_t)img->height;
  unsigned char *inside = malloc(n);
  if (!inside) {
    lw_image_free(own);
    return lw_error_set(err, LW_ENOMEM, "out of memory for the mask");
  }
  for (size_t k = 0; k < n; k++)
    inside[k] = p->mask == LW_MASK_ALPHA ? img->alpha[k] >= 0.5f : img->tone[k] <= 0.0f;
  lw_error e2;
  sc->boundary.kind = LW_BOUNDARY_MASK;
  sc->boundary.sdt = lw_sdt_grid(inside, img->width, img->height, &pl, &e2);
  free(inside);
  lw_image_free(own);
  if (!sc->boundary.sdt)
    return bad_key(p, "scene", p->mask == LW_MASK_ALPHA ? "mask" : "mask_image", e2.code, err, "%s (inside: %s)",
                   e2.msg, p->mask == LW_MASK_ALPHA ? "alpha at least 1/2" : "opaque, and tone below 1/2");
  return LW_OK;
}

static lw_status build_polygon(lw_scene *sc, const lw_params *p, lw_error *err)
{
  int count = lw_number_list(p->polygon, p->of_run ? 1 : 2, NULL, 0);
  if (count < 0)
    return bad_key(p, "scene", "polygon", LW_EINPUT, err, "expected numbers 'x y x y ...', got '%s'%s", p->polygon,
                   lw_number_list_hint(count));
  size_t n = (size_t)count;
  double *v = malloc((n ? n : 1) * sizeof *v);
  if (!v) return lw_error_set(err, LW_ENOMEM, "out of memory reading the polygon");
  lw_number_list(p->polygon, 1, v, count);
  lw_status st = LW_OK;
  if (n % 2 || n < 6) {
    st = bad_key(p, "scene", "polygon", LW_EINPUT, err,
                 "expected at least 3 vertices as 'x y' pairs, got %zu numbers%s", n,
                 n % 2 && n > 6 ? " (an odd count: one x or y is missing)" : "");
  } else {
    double *xs = malloc(n / 2 * sizeof *xs), *ys = malloc(n / 2 * sizeof *ys);
    if (!xs || !ys) st = lw_error_set(err, LW_ENOMEM, "out of memory reading the polygon");
    else {
      double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
      for (size_t i = 0; i < n / 2; i++) {
        xs[i] = v[2 * i];
        ys[i] = v[2 * i + 1];
        lo[0] = fmin(lo[0], xs[i]), hi[0] = fmax(hi[0], xs[i]);
        lo[1] = fmin(lo[1], ys[i]), hi[1] = fmax(hi[1], ys[i]);
      }
      lw_error e2;
      size_t ea, eb;
      /* its box must meet the page: a polygon beside it has no room on it */
      if (!(hi[0] >= 0 && lo[0] <= p->width && hi[1] >= 0 && lo[1] <= p->height))
        st = bad_key(p, "scene", "polygon", LW_EINPUT, err, "the polygon (x %g to %g, y %g to %g mm) lies off the "
                     "page of %g x %g mm", lo[0], hi[0], lo[1], hi[1], p->width, p->height);
      /* a polygon that crosses itself: a bowtie was "zero area" (its halves
      ** cancel), and a pentagram was taken by the even-odd rule, its centre
      ** outside, where an SVG's default fill has it inside (a run begun
      ** before 2026-12-05 keeps its shape) */
      else if (!lw_params_kept(p, "scene", "polygon") && lw_boundary_crossing(n / 2, xs, ys, &ea, &eb))
        st = bad_key(p, "scene", "polygon", LW_EINPUT, err, "the polygon crosses or touches itself: its edge from "
                     "vertex %zu meets the one from vertex %zu: expected a simple polygon, its edges meeting only at "
                     "their shared vertices (they count from 0; a star is given by its outline)", ea, eb);
      else if ((st = lw_boundary_polygon(&sc->boundary, n / 2, xs, ys, &e2)) != LW_OK)
        bad_key(p, "scene", "polygon", st, err, "%s", e2.msg);
      /* (a polygon in the margin was annealed, then drawn empty or cut,
      ** said only at the end) */
      else if (p->crop) {
        /* plot.crop's rectangle: the picture's where there is one (placed
        ** above), else the page inset by the margin */
        const lw_image_place *pl = &sc->image_place;
        const double c0[2] = {sc->image ? pl->x0 : p->margin, sc->image ? pl->y0 : p->margin};
        const double c1[2] = {sc->image ? pl->x0 + sc->image->width * pl->pixel : p->width - p->margin,
                              sc->image ? pl->y0 + sc->image->height * pl->pixel : p->height - p->margin};
        char box[160];
        if (sc->image)
          snprintf(box, sizeof box, "the picture's rectangle (x %g to %g, y %g to %g mm)", c0[0], c1[0], c0[1], c1[1]);
        else
          snprintf(box, sizeof box, "the page inset by scene.margin (%g mm)", p->margin);
        const size_t used = strlen(sc->note);
        if (lo[0] < c0[0] || hi[0] > c1[0] || lo[1] < c0[1] || hi[1] > c1[1])
          snprintf(sc->note + used, sizeof sc->note - used, "%sscene.polygon (x %g to %g, y %g to %g mm) reaches past "
                   "%s, where plot.crop cuts the drawing", used ? "\n" : "", lo[0], hi[0], lo[1], hi[1], box);
      }
    }
    free(xs);
    free(ys);
  }
  free(v);
  return st;
}

/* The per-segment terms that are on, in term order (the order sums run in). */
static void list_local_terms(lw_scene *sc)
{
  sc->n_local = 0;
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (sc->on[t] && lw_term_types[t].segment) sc->local[sc->n_local++] = (lw_term_id)t;
}

void lw_scene_term_ctx(const lw_scene *sc, lw_term_ctx ctx[LW_TERM_COUNT])
{
  for (int t = 0; t < LW_TERM_COUNT; t++) ctx[t] = (lw_term_ctx){.coef = sc->coef[t], .quad = &sc->quad};
  ctx[LW_TERM_STRAIN].mode = sc->strain_per_segment;
  ctx[LW_TERM_POTENTIAL].data = &sc->potential;
  ctx[LW_TERM_FIELD].data = &sc->field;
  ctx[LW_TERM_FIELD].mode = sc->field_axial;
  ctx[LW_TERM_BOUNDARY].data = &sc->boundary;
  ctx[LW_TERM_PAIR].data = &sc->pair;
  ctx[LW_TERM_PAIR].quad = &sc->pair_quad;
  ctx[LW_TERM_USER].data = sc->user_data;
  ctx[LW_TERM_USER].fn = sc->user_fn;
  ctx[LW_TERM_LOAD].data = sc->load;
  ctx[LW_TERM_TONE].data = &sc->tone;
  ctx[LW_TERM_TONE].quad = &sc->tone_quad;
  ctx[LW_TERM_CHEMICAL].data = sc->chem;
}

void lw_scene_layer_ctx(const lw_scene *sc, int k, lw_term_ctx ctx[LW_TERM_COUNT])
{
  lw_scene_term_ctx(sc, ctx);
  if (!sc->layers.n) return;
  ctx[LW_TERM_POTENTIAL].data = &sc->layer[k].potential;
  ctx[LW_TERM_FIELD].data = &sc->layer[k].field;
  ctx[LW_TERM_TONE].data = &sc->layer[k].tone;
}

lw_status lw_scene_set_user_term(lw_scene *sc, double coef, lw_user_term_fn fn, const void *data,
                                 lw_error *err)
{
  if (!isfinite(coef) || (coef != 0.0 && !fn))
    return lw_error_set(err, LW_EINPUT, "user term: expected a finite coefficient and a function, got %g and %s",
                        coef, fn ? "a function" : "none");
  sc->coef[LW_TERM_USER] = coef;
  sc->on[LW_TERM_USER] = coef != 0.0;
  sc->user_fn = coef != 0.0 ? fn : NULL;
  sc->user_data = coef != 0.0 ? data : NULL;
  list_local_terms(sc);
  return LW_OK;
}

/* One colour channel of the picture, through the luma's resize, blur and
** flattening (not its tone curve, which shapes the luma), at sc->image's size:
** flattened on its own, each channel's paper turns white, the light's colour
** with its unevenness. */
static lw_image *load_channel(lw_scene *sc, const lw_params *p, lw_image_channel which, lw_error *err)
{
  char full[2 * LW_PATH_MAX + 2];
  scene_relative(p, p->image, full);
  lw_image *img = lw_image_load_channel(full, p->image_max_pixels, which, NULL, err);
  if (!img) return NULL;
  if (img->width != sc->image->width || img->height != sc->image->height) {
    lw_image *r = lw_image_resize(img, sc->image->width, sc->image->height, err);
    lw_image_free(img);
    if (!(img = r)) return NULL;
  }
  double lo, hi;
  if (lw_image_blur(img, p->image_blur / sc->image_place.pixel, err) ||
      (p->image_flatten > 0 && lw_image_flatten(img, p->image_flatten / sc->image_place.pixel, &lo, &hi, err))) {
    lw_image_free(img);
    return NULL;
  }
  return img;
}

/* Each layer's target tone from the picture (layers.h). */
static lw_status layer_targets(lw_scene *sc, const lw_params *p, lw_error *err)
{
  const lw_layers_spec *ls = &sc->layers;
  const size_t n = (size_t)sc->image->width * (size_t)sc->image->height;
  for (int k = 0; k < ls->n; k++)
    if (!(sc->layer[k].target = lw_image_new(sc->image->width, sc->image->height, 0, err))) return err->code;
  if (ls->source == LW_LSRC_TONE) {
    for (int k = 0; k < ls->n; k++) {
      const double lo = ls->spec[k].tone_min, hi = ls->spec[k].tone_max;
      for (size_t q = 0; q < n; q++) {
        double a = (hi - sc->image->tone[q]) / (hi - lo);
        sc->layer[k].target->tone[q] = (float)(1.0 - (a < 0.0 ? 0.0 : a > 1.0 ? 1.0 : a));
      }
    }
    return LW_OK;
  }
  lw_image *ch[3] = {NULL, NULL, NULL};
  float *a = malloc((size_t)ls->n * n * sizeof *a);
  lw_status st = a ? LW_OK : lw_error_set(err, LW_ENOMEM, "out of memory separating the picture");
  for (int c = 0; !st && c < 3; c++)
    if (!(ch[c] = load_channel(sc, p, (lw_image_channel)(LW_IMAGE_RED + c), err))) st = err->code;
  if (!st) {
    unsigned char rgb[LW_LAYERS_MAX][3];
    for (int k = 0; k < ls->n; k++) memcpy(rgb[k], ls->spec[k].rgb, 3);
    lw_layers_separate(ch[0]->tone, ch[1]->tone, ch[2]->tone, n, ls->n, (const unsigned char (*)[3])rgb, a);
    for (int k = 0; k < ls->n; k++)
      for (size_t q = 0; q < n; q++) sc->layer[k].target->tone[q] = 1.0f - a[(size_t)k * n + q];
  }
  for (int c = 0; c < 3; c++) lw_image_free(ch[c]);
  free(a);
  return st;
}


/* The layers' targets, fields, potentials and tone rasters (layers.h). */
static lw_status build_layers(lw_scene *sc, const lw_params *p, lw_error *err)
{
  lw_status st = lw_layers_read(p, &sc->layers, err);
  if (st || !sc->layers.n) return st;
  if (p->pens != 1)
    return bad_key(p, "output", "pens", LW_EINPUT, err, "layers set the pens (one a layer): expected 1, got %d",
                   p->pens);
  if (p->pen_colors[0])
    return bad_key(p, "output", "pen_colors", LW_EINPUT, err, "layers set the pens' colours: use layers.colors");
  if (!sc->image) {
    if (sc->layers.source != LW_LSRC_TONE)
      return bad_key(p, "layers", "source", LW_EINPUT, err, "a separation needs a colour picture in scene.image");
  } else {
    if ((st = layer_targets(sc, p, err))) return st;
    const lw_image *t[LW_LAYERS_MAX];
    for (int k = 0; k < sc->layers.n; k++) t[k] = sc->layer[k].target;
    lw_layers_share(&sc->layers, t, p->ly_share_width && !before_key_of(p, "layers", "share_width"));
  }
  for (int k = 0; k < sc->layers.n; k++) {
    lw_layer *l = &sc->layer[k];
    if (sc->on[LW_TERM_FIELD]) {
      l->field = sc->field; /* the grid is borrowed: the scene frees it */
      l->field.turned = 1;
      l->field.turn_c = cos(sc->layers.spec[k].turn);
      l->field.turn_s = sin(sc->layers.spec[k].turn);
    }
    if (sc->on[LW_TERM_POTENTIAL]) {
      l->potential = sc->potential;
      l->potential.grid = NULL;
      if (sc->potential.kind == LW_POTENTIAL_GRID &&
          !(l->potential.grid = image_potential(sc, l->target, p, err)))
        return err->code;
    }
    if (sc->on[LW_TERM_TONE]) {
      lw_error e2;
      if ((st = lw_tone_init(&l->tone, l->target, &sc->image_place, p->tone_blur, sc->layers.spec[k].pen_width,
                             p->tone_ink, &e2)))
        return st == LW_EINPUT ? bad_key(p, "energy", "tone_blur", st, err, "%s", e2.msg)
                               : lw_error_set(err, st, "%s", e2.msg);
    }
  }
  return LW_OK;
}

/* The potential the scene names, about the page point (cx, cy). */
static lw_status build_potential(lw_scene *sc, const lw_params *p, double cx, double cy, lw_error *err)
{
  lw_potential *f = &sc->potential;
  f->cx = cx;
  f->cy = cy;
  switch (p->potential) {
  case LW_POT_CONSTANT:
    f->kind = LW_POTENTIAL_CONSTANT;
    f->value = p->potential_value;
    break;
  case LW_POT_RAMP:
    f->kind = LW_POTENTIAL_RAMP;
    f->ux = cos(p->potential_angle * DEG);
    f->uy = sin(p->potential_angle * DEG);
    /* half the page's extent along u, so Phi runs 0..1 corner to corner */
    f->scale = p->potential_scale > 0 ? p->potential_scale
               : 0.5 * (fabs(f->ux) * p->width + fabs(f->uy) * p->height);
    break;
  case LW_POT_RADIAL:
    f->kind = LW_POTENTIAL_RADIAL;
    f->scale = p->potential_scale > 0 ? p->potential_scale : 0.5 * hypot(p->width, p->height);
    break;
  case LW_POT_IMAGE:
    if (!sc->image) return bad_key(p, "scene", "potential", LW_EINPUT, err, "'image' needs scene.image");
    f->kind = LW_POTENTIAL_GRID;
    if (!(f->grid = image_potential(sc, sc->image, p, err)))
      return err->code;
    break;
  }
  return LW_OK;
}

/* scene.field = file: the grid of field_file, turned the page's way up,
** its lengths as field_file_scale says, placed over the picture (or where
** a picture of its shape would lie). */
static lw_status field_from_file(lw_scene *sc, const lw_params *p, lw_error *err)
{
  if (!p->field_file[0]) return bad_key(p, "scene", "field", LW_EINPUT, err, "'file' needs scene.field_file");
  char full[2 * LW_PATH_MAX + 2];
  scene_relative(p, p->field_file, full);
  lw_error e2;
  lw_grid2d *g = sc->field.grid = lw_fieldfile_read(full, 2, p->field_file_layout == LW_FFL_POINTS, &e2);
  if (!g) return bad_key(p, "scene", "field_file", e2.code, err, "%s", e2.msg);
  /* a node with a component not finite is a masked cell: no field there */
  const size_t nodes = (size_t)g->nx * (size_t)g->ny;
  size_t bad = 0;
  for (size_t k = 0; k < nodes; k++)
    if (!isfinite(g->data[2 * k]) || !isfinite(g->data[2 * k + 1])) {
      g->data[2 * k] = g->data[2 * k + 1] = 0.0;
      bad++;
    }
  if (p->field_file_y == LW_FFY_UP) {
    const size_t row = 2 * (size_t)g->nx;
    for (int j = 0; j < g->ny / 2; j++)
      for (size_t k = 0; k < row; k++) {
        double *a = g->data + (size_t)j * row + k, *b = g->data + (size_t)(g->ny - 1 - j) * row + k, t = *a;
        *a = *b;
        *b = t;
      }
    for (size_t k = 0; k < nodes; k++) g->data[2 * k + 1] = -g->data[2 * k + 1];
  }
  double longest = 0.0;
  for (size_t k = 0; k < nodes; k++) longest = fmax(longest, hypot(g->data[2 * k], g->data[2 * k + 1]));
  if (!(longest > 0.0) || !isfinite(longest))
    return bad_key(p, "scene", "field_file", LW_EINPUT, err, "%s: %s: expected a vector with a length somewhere",
                   full, !(longest > 0.0) ? (bad ? "every vector is zero or not finite" : "every vector is zero")
                                          : "a vector too long to measure (its length overflows)");
  for (size_t k = 0; k < nodes && p->field_file_scale != LW_FFS_NONE; k++) {
    double *d = g->data + 2 * k, n = p->field_file_scale == LW_FFS_MAX ? longest : hypot(d[0], d[1]);
    if (n > 0.0) d[0] /= n, d[1] /= n;
  }
  /* over the picture: a grid of another shape than the picture's would
  ** stretch the field over it, so it is refused; its rows (or columns) may
  ** be the picture's shape rounded (3 columns over a 2:1 picture take 1.5
  ** rows: 1 or 2).  Else fitted into the margin box as a picture of its
  ** shape: nx by ny cells of the spacings the file gives (1 by 1 a grid's). */
  const double cw = g->nx * g->hx, ch = g->ny * g->hy; /* the grid's extent, the file's units */
  lw_image_place pl = {0, 0, 0};
  double w, h;
  if (sc->image) {
    pl = sc->image_place;
    w = sc->image->width * pl.pixel;
    h = sc->image->height * pl.pixel;
    const double rows = g->nx * h * g->hx / (w * g->hy), cols = g->ny * w * g->hy / (h * g->hx);
    if (fabs(rows - g->ny) > 0.5 && fabs(cols - g->nx) > 0.5)
      return bad_key(p, "scene", "field_file", LW_EINPUT, err, "%s: a grid of %d columns x %d rows over a %d x %d "
                     "picture: expected the picture's shape (%d columns take %.0f rows), or no scene.image", full,
                     g->nx, g->ny, sc->image->width, sc->image->height, g->nx, rows);
  } else {
    const double bw = p->width - 2 * p->margin, bh = p->height - 2 * p->margin, s = fmin(bw / cw, bh / ch);
    w = cw * s;
    h = ch * s;
    pl.x0 = p->margin + 0.5 * (bw - w);
    pl.y0 = p->margin + 0.5 * (bh - h);
  }
  g->hx = w / g->nx;
  g->hy = h / g->ny;
  g->x0 = pl.x0 + 0.5 * g->hx;
  g->y0 = pl.y0 + 0.5 * g->hy;
  if (bad) {
    size_t used = strlen(sc->note);
    snprintf(sc->note + used, sizeof sc->note - used, "%sscene.field_file: %zu of the %zu nodes not finite (NaN or "
             "infinite): no field there", used ? "\n" : "", bad, nodes);
  }
  return LW_OK;
}

/* The field the scene names, about the page point (cx, cy). */
static lw_status build_field(lw_scene *sc, const lw_params *p, double cx, double cy, lw_error *err)
{
  lw_field *f = &sc->field;
  f->cx = cx;
  f->cy = cy;
  /* a run begun before 2026-12-05 has no line for it: no core, as it ran
  ** (a scene.ini written by hand beside a state takes the default) */
  f->core = before_key(p, "field_core") ? 0.0 : p->field_core < 0.0 ? p->segment_length : p->field_core;
  f->ux = cos(p->field_angle * DEG);
  f->uy = sin(p->field_angle * DEG);
  f->wavelength = p->field_wavelength;
  f->amplitude = p->field_amplitude;
  static const lw_field_kind kinds[] = {
    [LW_FLD_CONSTANT] = LW_FIELD_CONSTANT, [LW_FLD_RADIAL] = LW_FIELD_RADIAL,
    [LW_FLD_VORTEX] = LW_FIELD_VORTEX, [LW_FLD_WAVES] = LW_FIELD_WAVES,
    [LW_FLD_ETF] = LW_FIELD_GRID_AXIAL, [LW_FLD_GRADIENT] = LW_FIELD_GRID, [LW_FLD_FILE] = LW_FIELD_GRID,
  };
  f->kind = kinds[p->field];
  if (p->field == LW_FLD_FILE) return field_from_file(sc, p, err);
  if (p->field == LW_FLD_ETF || p->field == LW_FLD_GRADIENT) {
    const char *name = p->field == LW_FLD_ETF ? "etf" : "gradient";
    if (!sc->image) return bad_key(p, "scene", "field", LW_EINPUT, err, "'%s' needs scene.image", name);
    /* the flow has no sign: r'.v would reward either direction at random */
    if (p->field == LW_FLD_ETF && !sc->field_axial)
      return bad_key(p, "scene", "field", LW_EINPUT, err,
                     "'etf' is a direction without sign: it needs energy.field_mode = axial");
    double gentle[LW_IMAGEFIELD_GENTLE];
    f->grid = p->field == LW_FLD_ETF
              ? lw_imagefield_etf(sc->image, &sc->image_place, p->field_sigma, p->field_flat,
                                  p->field_angle * DEG, gentle, err)
              : lw_imagefield_gradient(sc->image, &sc->image_place, p->field_flat, gentle, err);
    if (!f->grid) return err->code;
    /* (three quarters: the bundled picture's smooth parts, blurred, are
    ** over half of it, and a gradient hatching there is meant to fade) */
    if (gentle[0] > 0.75) {
      size_t used = strlen(sc->note);
      /* (shares rounded down alike: a tenth of field_flat, rounded up, left
      ** "100 %" where field_flat itself left "over 99 %") */
      char share[32] = "all";
      if (gentle[0] < 1.0) snprintf(share, sizeof share, "over %d %%", (int)(100.0 * gentle[0]));
      used += (size_t)snprintf(sc->note + used, sizeof sc->note - used, "%sscene.field_flat: on %s of the picture "
                               "the tone changes slower than field_flat (%g tone/mm) or not at all, and there the "
                               "field %s; where that is a smooth picture, not flat colour, a smaller field_flat "
                               "follows it (", used ? "\n" : "", share,
                               p->field_flat, p->field == LW_FLD_ETF ? "turns to field_angle" : "fades to 0");
      for (int k = 1; k < LW_IMAGEFIELD_GENTLE && used < sizeof sc->note; k++)
        used += (size_t)snprintf(sc->note + used, sizeof sc->note - used, "%s%g leaves %d %%", k > 1 ? ", " : "",
                                 p->field_flat * pow(10.0, -k), (int)(100.0 * gentle[k]));
      if (used < sizeof sc->note) snprintf(sc->note + used, sizeof sc->note - used, "; docs/IMAGES.md)");
    }
  }
  return LW_OK;
}

static lw_status build_boundary(lw_scene *sc, const lw_params *p, lw_error *err)
{
  lw_status st;
  lw_boundary *b = &sc->boundary;
  switch (p->boundary) {
  case LW_BND_RECT:
  case LW_BND_CIRCLE:
    if ((st = margin_ok(p, err))) return st;
    if (p->boundary == LW_BND_RECT) {
      b->kind = LW_BOUNDARY_RECT;
      b->x0 = p->margin;
      b->y0 = p->margin;
      b->x1 = p->width - p->margin;
      b->y1 = p->height - p->margin;
    } else {
      b->kind = LW_BOUNDARY_CIRCLE;
      b->cx = 0.5 * p->width;
      b->cy = 0.5 * p->height;
      b->radius = 0.5 * fmin(p->width, p->height) - p->margin;
    }
    break;
  case LW_BND_POLYGON:
    /* the margin frames no polygon, but without a picture it sets plot.crop's
    ** rectangle: an empty one failed the drawing after every sweep had run */
    if (p->crop && !p->image[0] && (st = margin_ok(p, err))) return st;
    st = build_polygon(sc, p, err);
    if (st) return st;
    break;
  case LW_BND_MASK:
    if ((st = build_mask(sc, p, err))) return st;
    break;
  }
  if (p->boundary != LW_BND_MASK && p->mask != LW_MASK_NONE)
    return bad_key(p, "scene", "mask", LW_EINPUT, err, "a mask needs scene.boundary = mask");
  b->slope = b->kind == LW_BOUNDARY_MASK ? lw_boundary_mask_slope(b->sdt) : 1.0;
  b->clearance = p->boundary_clearance;
  return LW_OK;
}

/* The pair and tone terms' node rules, and the pair kernel's radii. */
static lw_status build_pair(lw_scene *sc, const lw_params *p, lw_error *err)
{
  lw_status st;
  if ((st = term_nodes(p, sc, sc->on[LW_TERM_PAIR], "pair_quadrature", p->pair_quadrature, &sc->pair_quad, err)) ||
      (st = term_nodes(p, sc, sc->on[LW_TERM_TONE], "tone_quadrature", p->tone_quadrature, &sc->tone_quad, err)))
    return st;
  /* (a run begun before the rule, whose scene.ini holds a smaller one,
  ** still resumes and measures as it ran; unless --set changes the radius
  ** or the nodes: `energy --set` measured a radius a run refuses) */
  const double least = ceil(1e3 * lw_pair_near_least(&sc->pair_quad)) / 1e3;
  const lw_param_def *d = lw_params_find("energy", "pair_near");
  const char *nodes = p->pair_quadrature > 0 ? "pair_quadrature" : "quadrature";
  const int near_set = lw_params_given(p, d), nodes_set = lw_params_given(p, lw_params_find("energy", nodes));
  if (sc->on[LW_TERM_PAIR] && p->pair_near > 0.0 && p->pair_near < least && (!p->of_run || near_set || nodes_set)) {
    /* blame what the user set: the radius, or the nodes under the default one */
    const char *key = near_set || (!p->of_run && p->line[d - lw_param_table]) ? "pair_near" : nodes;
    return bad_key(p, "energy", key, LW_EINPUT, err, "energy.pair_near = %g is less than %.3f, the least at %d pair "
                   "nodes (energy.%s): expected pair_near 0 (off) or at least that (closer, a line "
                   "crossing another between their samples is taken only in part: docs/ACCURACY.md, \"Near "
                   "field\")", p->pair_near, least, sc->pair_quad.n, nodes);
  }
  lw_pair_ctx_init(&sc->pair, p->pair_cutoff, p->pair_near);
  sc->pair_gap_max = sc->on[LW_TERM_PAIR] && p->pair_cutoff > 0.0 ? LW_PAIR_GAP_SHARE * p->pair_cutoff : 0.0;
  return LW_OK;
}

static lw_status scene_build(lw_scene *sc, const lw_params *p, lw_error *err)
{
  sc->width = p->width;
  sc->height = p->height;
  double coef[LW_TERM_COUNT] = {
    [LW_TERM_STRAIN] = p->strain, [LW_TERM_BENDING] = p->bending,
    [LW_TERM_POTENTIAL] = p->potential_coef, [LW_TERM_FIELD] = p->field_coef,
    [LW_TERM_PAIR] = p->pair, [LW_TERM_BOUNDARY] = p->boundary_coef,
    [LW_TERM_PARAM] = p->parametrisation, [LW_TERM_TONE] = p->tone,
  };
  sc->load[0] = p->dyn_rho * p->dyn_gravity_x + p->dyn_force_x;
  sc->load[1] = p->dyn_rho * p->dyn_gravity_y + p->dyn_force_y;
  coef[LW_TERM_LOAD] = sc->load[0] != 0.0 || sc->load[1] != 0.0;
  sc->chem[0] = p->chem_spline;
  sc->chem[1] = p->chem_length;
  coef[LW_TERM_CHEMICAL] = sc->chem[0] != 0.0 || sc->chem[1] != 0.0;
  sc->transdim = !p->fixed_count;
  /* a cap below the placed splines' count was raised to it without a word,
  ** and lines grew past the cap the scene set (births start at init.segments
  ** under init.from too); an unset cap gives way, as does the default's
  ** value in a run's scene.ini, which writes every key (an explicit 16 in a
  ** scene was taken for the default and raised, where 17 was refused), and a
  ** run begun before 2026-12-05 keeps its cap */
  const lw_param_def *cap = lw_params_find("moves", "max_segments");
  const int cap_line = lw_params_line(p, "moves", "max_segments");
  const int cap_unset = strtod(cap->def, NULL) == p->max_segments && (!cap_line || (p->run_header && cap_line > 0));
  if (sc->transdim && p->max_segments < p->segments && !cap_unset && !lw_params_kept(p, "moves", "max_segments"))
    return bad_key(p, "moves", "max_segments", LW_EINPUT, err, "expected at least init.segments = %d, the count "
                   "placed and born splines start with, got %d", p->segments, p->max_segments);
  sc->max_segments = (size_t)(p->max_segments > p->segments ? p->max_segments : p->segments);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    sc->coef[t] = coef[t];
    sc->on[t] = coef[t] != 0.0;
  }
  list_local_terms(sc);
  sc->strain_per_segment = p->strain_mode == LW_STRAIN_SEGMENT;
  sc->field_axial = p->field_mode == LW_FIELDMODE_AXIAL;
  sc->min_speed = p->min_speed;
  sc->regularity = p->regularity > 1.0 ? p->regularity : 0.0;
  lw_status st = lw_quad_init(&sc->quad, p->quadrature, err);
  if (st) return st;
  if ((st = build_pair(sc, p, err))) return st;
  /* -1 is the page centre; a value between it and 0 meant it too, silently
  ** (and still does in a run begun before 2026-12-05) */
  static const char *const centre_key[2] = {"center_x", "center_y"};
  const double centre[2] = {p->center_x, p->center_y};
  for (int k = 0; k < 2; k++)
    if (centre[k] < 0.0 && centre[k] != -1.0 && !lw_params_kept(p, "scene", centre_key[k]))
      return bad_key(p, "scene", centre_key[k], LW_EINPUT, err, "expected -1 (the page centre) or a coordinate >= 0, "
                     "got %g", centre[k]);
  if (p->field_core < 0.0 && p->field_core != -1.0)
    return bad_key(p, "scene", "field_core", LW_EINPUT, err, "expected -1 (init.segment_length) or a radius >= 0, "
                   "got %g", p->field_core);
  double cx = p->center_x >= 0 ? p->center_x : 0.5 * p->width;
  double cy = p->center_y >= 0 ? p->center_y : 0.5 * p->height;

  if (p->image[0] && (st = build_image(sc, p, err))) return st;
  if (p->fidelity_reference[0]) {
    if ((st = margin_ok(p, err))) return st;
    sc->reference = load_picture(sc, p, "output", "fidelity_reference", p->fidelity_reference, LW_IMAGE_LUMA,
                                 &sc->reference_place, err);
    if (!sc->reference) return err->code;
    if ((st = scored_side_ok(p, "output", "fidelity_reference", sc->reference, err))) return st;
  }

  if (sc->on[LW_TERM_POTENTIAL] && (st = build_potential(sc, p, cx, cy, err))) return st;
  if (sc->on[LW_TERM_FIELD] && (st = build_field(sc, p, cx, cy, err))) return st;
  if (sc->on[LW_TERM_TONE]) {
    if (!sc->image) return bad_key(p, "energy", "tone", LW_EINPUT, err, "the tone term needs scene.image");
    lw_error e2;
    if ((st = lw_tone_init(&sc->tone, sc->image, &sc->image_place, p->tone_blur, p->pen_width, p->tone_ink, &e2)))
      return st == LW_EINPUT ? bad_key(p, "energy", "tone_blur", st, err, "%s", e2.msg)
                             : lw_error_set(err, st, "%s", e2.msg);
  }
  if (p->min_spacing > 0.0) {
    if (!sc->on[LW_TERM_PAIR]) {
      /* energy --set energy.pair=0 on a run with the rule: the --set is what
      ** to change, not the run's scene.ini */
      char where[LW_PATH_MAX + 32];
      lw_params_origin(p, lw_params_find("energy", "pair"), where, sizeof where);
      return bad_key(p, "energy", "min_spacing", LW_EINPUT, err,
                     "the spacing constraint looks in the pair term's cell grid: it needs energy.pair, which is 0 "
                     "(%s); set energy.min_spacing = 0 too to go without both", where);
    }
    if (p->pair_cutoff > 0.0 && p->min_spacing > p->pair_cutoff)
      return bad_key(p, "energy", "min_spacing", LW_EINPUT, err,
                     "expected at most energy.pair_cutoff (%.10g mm), got %.10g", p->pair_cutoff, p->min_spacing);
    sc->min_spacing = p->min_spacing;
  }
  if (p->field_preview && !sc->on[LW_TERM_FIELD])
    return bad_key(p, "output", "field_preview", LW_EINPUT, err,
                   "the scene has no field to preview (energy.field is 0)");
  if (p->preview_image && !sc->image)
    return bad_key(p, "output", "preview_image", LW_EINPUT, err, "the scene has no picture to paint under the lines "
                   "(scene.image is empty)");

  if ((st = build_boundary(sc, p, err))) return st;
  if (sc->image) dark_note(sc, p);
  if (sc->image) unread_picture_note(sc, p);
  if (sc->image && (sc->on[LW_TERM_TONE] || (sc->on[LW_TERM_POTENTIAL] && p->potential == LW_POT_IMAGE)))
    thin_note(sc, p, "image", sc->image, &sc->image_place);
  return build_layers(sc, p, err);
}

/* A placed segment's samples further apart than a blur its terms take the
** picture at, where no pair cutoff holds the stretch (the pair gap check):
** an annealer then stretches segments over the picture's detail between
** them (7e-2 of the potential hidden: docs/NUMERICS.md, "What the
** clearance does not cover"), so the run says so.  Held by a cutoff, as in
** the photo preset (gaps 1.27 times its potential's blur), it hid at most
** 3e-4, and params/study.ini (1.43 times) 5e-5: there the note waits for
** gaps 1.5 times the blur, where the placed samples alone miss the detail
** (energy.tone_quadrature = 2 under the preset, 1.54 times: 9 % of the
** tone hidden). */
static void note_blur_gaps(lw_scene *sc, const lw_params *p)
{
  if (!sc->image) return;
  const int held = sc->pair_gap_max > 0.0;
  /* the detail's scale: the term's blur and the picture's own, or without
  ** either its pixels */
  const double ib = p->image_blur, px = sc->image_place.pixel;
  const double pb = hypot(p->potential_blur, ib), tb = hypot(p->tone_blur, ib);
  const struct {
    int on;
    double gap, scale;
    const char *key, *nodes;
    int most; /* at LW_QUAD_MAX nodes: only a wider blur closes it */
  } g[2] = {{sc->on[LW_TERM_POTENTIAL] && p->potential == LW_POT_IMAGE, p->segment_length * sc->quad.spacing,
             pb > 0.0 ? pb : px, "scene.potential_blur", "energy.quadrature", sc->quad.n >= LW_QUAD_MAX},
            {sc->on[LW_TERM_TONE], p->segment_length * sc->tone_quad.spacing, tb > 0.0 ? tb : px, "energy.tone_blur",
             "energy.tone_quadrature", sc->tone_quad.n >= LW_QUAD_MAX}};
  for (int k = 0; k < 2; k++) {
    /* (held, a picture's bare pixels are a texture the samples may step
    ** over: every sharp picture would get the note) */
    const int blurred = k ? tb > 0.0 : pb > 0.0;
    if (!g[k].on || (held && !blurred) || !(g[k].gap > (held ? 1.5 : 1.0) * g[k].scale)) continue;
    size_t used = strlen(sc->note);
    char more[96] = "";
    if (!g[k].most) snprintf(more, sizeof more, "more nodes (%s) or ", g[k].nodes);
    snprintf(sc->note + used, sizeof sc->note - used, "%sthe placed segments' samples lie up to %.3g mm apart, more "
             "than the picture's detail under %s (%.3g mm, with scene.image_blur and the pixels): %s, hidden from "
             "the quadrature (docs/NUMERICS.md); %sa wider blur closes it%s",
             used ? "\n" : "", g[k].gap, g[k].key, g[k].scale,
             held ? "the samples step over it" : "annealed segments can stretch over it", more,
             held ? "" : ", and energy.pair > 0 with a pair_cutoff holds the stretch");
  }
}

/* The share of a field grid's node pairs (neighbours along x or y, both
** with a direction) over which the field turns faster than a radian in
** `len` mm (axial: the angle between the axes): a data field's own detail,
** which its node spacing alone is not (a smooth field sampled finely was
** noted, a checkerboard of 1.2 mm not). */
static double grid_turning_share(const lw_grid2d *g, int axial, double len)
{
  size_t pairs = 0, fast = 0;
  for (int j = 0; j < g->ny; j++)
    for (int i = 0; i < g->nx; i++) {
      const double *a = g->data + 2 * ((size_t)j * (size_t)g->nx + (size_t)i), la = hypot(a[0], a[1]);
      for (int d = 0; d < 2; d++) {
        if (d ? j + 1 >= g->ny : i + 1 >= g->nx) continue;
        const double *b = d ? a + 2 * (size_t)g->nx : a + 2, lb = hypot(b[0], b[1]);
        if (!(la > 0.0 && lb > 0.0)) continue;
        double c = (a[0] * b[0] + a[1] * b[1]) / (la * lb);
        c = fmin(1.0, fmax(-1.0, axial ? fabs(c) : c));
        pairs++;
        fast += acos(c) * len > (d ? g->hy : g->hx);
      }
    }
  return pairs ? (double)fast / (double)pairs : 0.0;
}

/* The field's own detail finer than the samples along a segment: there the
** annealing bends segments between the samples to follow the field where
** they are and not between them, and the quadrature misses what it costs
** (an adversary, 2026-12-07: field = gradient on params/study.ini hid
** 1.9e-2 of the field term, 19 % unblurred at 600 pixels; waves of 4 mm
** 3 %, 16 mm 8e-4, 30 mm 2e-8; a checkerboard of directions in a field
** file, nodes 1.2 mm apart, 1.3e-2).  The detail: the blur or pixels the
** picture's field varies over, the length over which the waves turn a
** radian, 1 / (k^2 A), or a field file's own turning (a tenth of its
** neighbouring nodes turning a radian within the samples' spacing).  No
** check holds a segment to it (docs/NUMERICS.md, "What the clearance does
** not cover"). */
static void note_field_detail(lw_scene *sc, const lw_params *p)
{
  if (!sc->on[LW_TERM_FIELD]) return;
  const double gap = p->segment_length * sc->quad.spacing, px = sc->image ? sc->image_place.pixel : 0.0;
  const double k = 2.0 * M_PI / p->field_wavelength, etf = hypot(p->field_sigma, p->image_blur);
  double scale = INFINITY, share;
  const char *what = "", *closes;
  char detail[200];
  switch (p->field) {
  case LW_FLD_ETF:
    scale = etf > 0.0 ? etf : px;
    what = etf > 0.0 ? "scene.field_sigma with scene.image_blur" : "the picture's pixels";
    closes = "a wider scene.field_sigma";
    break;
  case LW_FLD_GRADIENT:
    scale = p->image_blur > 0.0 ? p->image_blur : px;
    what = p->image_blur > 0.0 ? "scene.image_blur" : "the picture's pixels";
    closes = "a wider scene.image_blur";
    break;
  case LW_FLD_WAVES:
    if (p->field_amplitude != 0.0) scale = 1.0 / (k * k * fabs(p->field_amplitude));
    what = "the length over which the waves turn a radian, wavelength^2 / (4 pi^2 amplitude)";
    closes = "a longer scene.field_wavelength or a smaller amplitude";
    break;
  case LW_FLD_FILE:
    if (!((share = grid_turning_share(sc->field.grid, sc->field_axial, gap)) > 0.1)) return;
    snprintf(detail, sizeof detail, "scene.field_file's field turns a radian within it between %.0f %% of its "
             "neighbouring nodes", 100.0 * share);
    closes = "a smoother field";
    break;
  default:
    return; /* (constant; radial and vortex: their core, scene.field_core, has its own stated accuracy) */
  }
  if (p->field != LW_FLD_FILE) {
    if (!(gap > scale)) return;
    snprintf(detail, sizeof detail, "%.3g mm: %s", scale, what);
  }
  char more[96] = "";
  if (sc->quad.n < LW_QUAD_MAX) snprintf(more, sizeof more, " or more nodes (energy.quadrature)");
  size_t used = strlen(sc->note);
  snprintf(sc->note + used, sizeof sc->note - used, "%sscene.field: the placed segments' samples lie up to %.3g mm "
           "apart, more than the field's detail (%s): annealed segments can bend between the samples, the field's "
           "term hidden from the quadrature (docs/NUMERICS.md); %s%s closes it", used ? "\n" : "", gap, detail,
           closes, more);
}

/* The pair term's product rule alone, with nothing to keep strokes apart:
** where they touch or cross it misses energy, and the chain finds such
** states (a photograph annealed so read its pair energy 11.6 % low). */
static void note_pair_unguarded(lw_scene *sc, const lw_params *p)
{
  if (!sc->on[LW_TERM_PAIR] || p->pair_near > 0.0 || p->min_spacing > 0.0) return;
  size_t used = strlen(sc->note);
  snprintf(sc->note + used, sizeof sc->note - used, "%senergy.pair_near = 0 and energy.min_spacing = 0: strokes may "
           "touch and cross, where the pair term's product rule alone reads their energy low, and the annealing "
           "seeks that out (up to 40 %% where two curves cross, docs/ACCURACY.md); a near field (energy.pair_near = "
           "1.5) or a spacing keeps the energy whole", used ? "\n" : "");
}

lw_status lw_scene_init(lw_scene *sc, const lw_params *p, lw_error *err)
{
  memset(sc, 0, sizeof *sc);
  lw_status st = scene_build(sc, p, err);
  if (st) {
    lw_scene_clear(sc);
  } else {
    note_blur_gaps(sc, p);
    note_field_detail(sc, p);
    note_pair_unguarded(sc, p);
  }
  return st;
}

void lw_scene_clear(lw_scene *sc)
{
  lw_potential_clear(&sc->potential);
  lw_field_clear(&sc->field);
  lw_boundary_clear(&sc->boundary);
  lw_tone_clear(&sc->tone);
  for (int k = 0; k < LW_LAYERS_MAX; k++) {
    lw_potential_clear(&sc->layer[k].potential);
    lw_tone_clear(&sc->layer[k].tone);
    lw_image_free(sc->layer[k].target);
    sc->layer[k].target = NULL;
  }
  lw_image_free(sc->image);
  sc->image = NULL;
  lw_image_free(sc->reference);
  sc->reference = NULL;
}
