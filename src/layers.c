/* layers.c -- the [layers] keys and colour separation (layers.h). */
#include "linewise/layers.h"

#include <ctype.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "linewise/number.h"
#include "linewise/output.h"

/* "file:line: key 'layers.key': ..." */
static lw_status bad(const lw_params *p, const char *key, lw_error *err, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static lw_status bad(const lw_params *p, const char *key, lw_error *err, const char *fmt, ...)
{
  char where[LW_PATH_MAX + 32], what[LW_ERROR_MSG];
  lw_params_origin(p, lw_params_find("layers", key), where, sizeof where);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  return lw_error_set(err, LW_EINPUT, "%s: key 'layers.%s': %s", where, key, what);
}

/* 1 if key holds something other than its default (a run's scene.ini
** writes every key back, so where a key was set says nothing). */
static int given(const lw_params *p, const char *key)
{
  if (!strcmp(key, "source")) return p->ly_source != LW_LSRC_TONE;
  const lw_param_def *d = lw_params_find("layers", key);
  return ((const char *)p + d->offset)[0] != '\0';
}

/* One number a layer from text into v[n] (empty: leave the defaults);
** within [lo, hi]. */
static lw_status per_layer(const lw_params *p, const char *key, const char *text, int n, double lo, double hi,
                           double *v, lw_error *err)
{
  if (!text[0]) return LW_OK;
  double got[LW_LAYERS_MAX];
  int count = lw_number_list(text, p->of_run ? 1 : 2, got, LW_LAYERS_MAX);
  if (count < 0)
    return bad(p, key, err, "expected %d number%s (one a layer), got '%s'%s", n, n == 1 ? "" : "s", text,
               lw_number_list_hint(count));
  if (count != n)
    return bad(p, key, err, "expected %d number%s (one a layer of layers.names), got %d", n, n == 1 ? "" : "s",
               count);
  for (int k = 0; k < n; k++) {
    if (!(got[k] >= lo && got[k] <= hi))
      return bad(p, key, err, "expected values from %g to %g, got %g for layer %d", lo, hi, got[k], k + 1);
    v[k] = got[k];
  }
  return LW_OK;
}

static const unsigned char process[4][3] = {{0, 255, 255}, {255, 0, 255}, {255, 255, 0}, {0, 0, 0}};
static const char *const process_name[4] = {"cyan", "magenta", "yellow", "black"};

/* The process ink rgb is plainly a shade of (a pen's true colour, #00a0e0
** for a cyan): the nearest, at under half the distance of the next; -1
** where none is (a grey, white: as near cyan as magenta). */
static int plain_ink(const unsigned char *rgb)
{
  double d[4];
  int best = 0, second = 1;
  for (int k = 0; k < 4; k++) {
    d[k] = 0.0;
    for (int c = 0; c < 3; c++) d[k] += ((double)rgb[c] - process[k][c]) * ((double)rgb[c] - process[k][c]);
  }
  if (d[1] < d[0]) best = 1, second = 0;
  for (int k = 2; k < 4; k++)
    if (d[k] < d[best]) second = best, best = k;
    else if (d[k] < d[second]) second = k;
  return sqrt(d[best]) < 0.5 * sqrt(d[second]) ? best : -1;
}

/* Under a separation a layer draws the ink of its colour, whatever it is
** called: a layer named for a process ink whose colour is another ink's
** (cmyk's layers renamed "yellow cyan magenta black" to plot yellow first;
** cmyk's own names over colours given in another order) labelled its SVG
** layer and G-code pen with the wrong ink, unsaid. */
static lw_status names_match_inks(const lw_params *p, const lw_layers_spec *ls, unsigned char (*rgb)[3],
                                  lw_error *err)
{
  /* (a run begun before the check resumes as it began) */
  if (ls->source == LW_LSRC_TONE || lw_params_kept(p, "layers", "names")) return LW_OK;
  for (int k = 0; k < ls->n; k++)
    for (int ink = 0, near = plain_ink(rgb[k]); ink < 4; ink++) {
      if (strcasecmp(ls->spec[k].name, process_name[ink]) || near < 0 || near == ink) continue;
      return bad(p, p->ly_names[0] ? "names" : "colors", err, "layer %d is named '%s', but its colour #%02x%02x%02x is "
                 "a %s, which it draws (a separation draws each layer's colour%s): expected the names and "
                 "layers.colors in one order (to plot yellow first under cmyk: names = yellow cyan magenta black, "
                 "colors = #ffff00 #00ffff #ff00ff #000000)", k + 1, ls->spec[k].name, rgb[k][0], rgb[k][1], rgb[k][2],
                 process_name[near], p->ly_colors[0] ? "" : "; cmyk's are cyan, magenta, yellow, black in that order");
    }
  return LW_OK;
}

lw_status lw_layers_read(const lw_params *p, lw_layers_spec *ls, lw_error *err)
{
  memset(ls, 0, sizeof *ls);
  ls->source = p->ly_source;
  ls->apart = p->ly_apart;
  static const char *const keys[] = {"source", "colors", "turn", "tone_min", "tone_max", "pen_width"};
  /* cmyk names its own four pens */
  const char *names = p->ly_names[0] || ls->source != LW_LSRC_CMYK ? p->ly_names : "cyan magenta yellow black";
  if (!names[0]) {
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
      if (given(p, keys[k])) return bad(p, keys[k], err, "needs layers.names (the layers it describes)");
    return LW_OK;
  }
  int n = 0;
  for (const char *c = names;;) {
    c += strspn(c, " \t,");
    if (!*c) break;
    size_t len = strcspn(c, " \t,");
    if (n == LW_LAYERS_MAX) return bad(p, "names", err, "expected at most %d layers", LW_LAYERS_MAX);
    if (len >= sizeof ls->spec[n].name)
      return bad(p, "names", err, "expected names of at most %zu characters", sizeof ls->spec[n].name - 1);
    /* the name labels the pen's SVG layer: nothing XML would read as markup */
    for (size_t q = 0; q < len; q++)
      if (!isalnum((unsigned char)c[q]) && !strchr("-_.", c[q]))
        return bad(p, "names", err, "expected names of ASCII letters, digits, '-', '_' and '.', got '%.*s'", (int)len,
                   c);
    memcpy(ls->spec[n].name, c, len);
    ls->spec[n].name[len] = '\0';
    /* a name says which pen a layer is: two alike would leave the plotter guessing */
    for (int q = 0; q < n; q++)
      if (!strcmp(ls->spec[q].name, ls->spec[n].name))
        return bad(p, "names", err, "expected names that differ, got '%s' twice", ls->spec[n].name);
    n++;
    c += len;
  }
  if (!n) return bad(p, "names", err, "expected at least one name, got '%s'", names);
  ls->n = n;
  if (ls->source == LW_LSRC_CMYK && n != 4)
    return bad(p, "source", err, "'cmyk' needs 4 layers (cyan magenta yellow black), layers.names has %d", n);
  double turn[LW_LAYERS_MAX] = {0}, lo[LW_LAYERS_MAX] = {0}, hi[LW_LAYERS_MAX], width[LW_LAYERS_MAX];
  for (int k = 0; k < n; k++) {
    hi[k] = 1.0;
    width[k] = p->pen_width;
  }
  lw_status st;
  if ((st = per_layer(p, "turn", p->ly_turn, n, -360, 360, turn, err)) ||
      (st = per_layer(p, "tone_min", p->ly_tone_min, n, 0, 1, lo, err)) ||
      (st = per_layer(p, "tone_max", p->ly_tone_max, n, 0, 1, hi, err)) ||
      (st = per_layer(p, "pen_width", p->ly_pen_width, n, 1e-3, 100, width, err)))
    return st;
  /* the bound given last is blamed: one of --set over the scene file's, a
  ** later line over an earlier (a tone_min raised by --set was blamed on the
  ** file's tone_max); of two --set, whose order is not kept, tone_max */
  const int at_min = lw_params_line(p, "layers", "tone_min"),
            at_max = lw_params_line(p, "layers", "tone_max");
  const int min_last = given(p, "tone_min") && (!given(p, "tone_max") || (at_min < 0 && at_max > 0) ||
                                                 (at_min > 0 && at_max > 0 && at_min > at_max));
  const char *last = min_last ? "tone_min" : "tone_max";
  for (int k = 0; k < n; k++)
    if (!(lo[k] < hi[k]))
      return bad(p, last, err, "expected layers.tone_min < layers.tone_max, got %g and %g for layer %d", lo[k], hi[k],
                 k + 1);
  if (ls->source != LW_LSRC_TONE && (given(p, "tone_min") || given(p, "tone_max")))
    return bad(p, given(p, "tone_min") ? "tone_min" : "tone_max", err,
               "a tone range needs layers.source = tone (a separation sets each pen's target)");
  unsigned char rgb[LW_LAYERS_MAX][3] = {{0}};
  if (p->ly_colors[0]) {
    int count = lw_output_colors_parse(p->ly_colors, rgb, LW_LAYERS_MAX);
    if (count != n)
      return bad(p, "colors", err, "expected %d colour%s '#rrggbb' or '#rgb' (one a layer), got '%s'", n,
                 n == 1 ? "" : "s", p->ly_colors);
  } else if (ls->source == LW_LSRC_CMYK) {
    memcpy(rgb, process, sizeof process);
  } else if (ls->source == LW_LSRC_PALETTE) {
    return bad(p, "source", err, "'palette' needs layers.colors: the pens to separate the picture into");
  }
  if ((st = names_match_inks(p, ls, rgb, err))) return st;
  lw_layers_share(ls, NULL, 0);
  for (int k = 0; k < n; k++) {
    ls->spec[k].turn = turn[k] * M_PI / 180.0;
    ls->spec[k].tone_min = lo[k];
    ls->spec[k].tone_max = hi[k];
    ls->spec[k].pen_width = width[k];
    memcpy(ls->spec[k].rgb, rgb[k], 3);
  }
  return LW_OK;
}

void lw_layers_share(lw_layers_spec *ls, const lw_image *const *target, int by_width)
{
  double ink[LW_LAYERS_MAX] = {0}, total = 0.0;
  for (int k = 0; target && k < ls->n; k++) {
    const size_t n = (size_t)target[k]->width * (size_t)target[k]->height;
    for (size_t q = 0; q < n; q++) ink[k] += 1.0 - target[k]->tone[q];
    /* a fine pen's layer was given splines by its ink alone and drew 0.34 of
    ** a full tone that a wide pen's drew at 0.52 */
    if (by_width) ink[k] /= ls->spec[k].pen_width;
    total += ink[k];
  }
  ls->cum[0] = 0.0;
  for (int k = 0; k < ls->n; k++) ls->cum[k + 1] = total > 0.0 ? ls->cum[k] + ink[k] / total : (k + 1.0) / ls->n;
  ls->cum[ls->n] = 1.0;
}

/* ---- separation ---------------------------------------------------------- */

/* The normal equations of one pixel: M = U^T U + lambda I, b = U^T d. */
typedef struct {
  int k;
  double M[LW_LAYERS_MAX][LW_LAYERS_MAX];
} normal;

/* Solves M_FF z_F = b_F - M_FB a_B for the free set F (free[j] = 1) into
** z (entries of F only) by Cholesky: M_FF is positive definite (the ridge
** keeps its pivots >= lambda), and at most 16 x 16. */
static void solve_free(const normal *nm, const double *b, const double *a, const int *free_, double *z)
{
  int idx[LW_LAYERS_MAX], nf = 0;
  for (int j = 0; j < nm->k; j++)
    if (free_[j]) idx[nf++] = j;
  double m[LW_LAYERS_MAX * LW_LAYERS_MAX], r[LW_LAYERS_MAX], x[LW_LAYERS_MAX];
  for (int i = 0; i < nf; i++) {
    r[i] = b[idx[i]];
    for (int j = 0; j < nm->k; j++)
      if (!free_[j]) r[i] -= nm->M[idx[i]][j] * a[j];
    for (int j = 0; j < nf; j++) m[i * nf + j] = nm->M[idx[i]][idx[j]];
  }
  /* Cholesky m = L L^T in place (lower triangle), then two triangular solves */
  for (int j = 0; j < nf; j++) {
    double d = m[j * nf + j];
    for (int q = 0; q < j; q++) d -= m[j * nf + q] * m[j * nf + q];
    m[j * nf + j] = sqrt(d);
    for (int i = j + 1; i < nf; i++) {
      double v = m[i * nf + j];
      for (int q = 0; q < j; q++) v -= m[i * nf + q] * m[j * nf + q];
      m[i * nf + j] = v / m[j * nf + j];
    }
  }
  for (int i = 0; i < nf; i++) {
    double v = r[i];
    for (int q = 0; q < i; q++) v -= m[i * nf + q] * x[q];
    x[i] = v / m[i * nf + i];
  }
  for (int i = nf - 1; i >= 0; i--) {
    double v = x[i];
    for (int q = i + 1; q < nf; q++) v -= m[q * nf + i] * x[q];
    x[i] = v / m[i * nf + i];
  }
  for (int i = 0; i < nf; i++) z[idx[i]] = x[i];
}

/* min 1/2 a^T M a - b^T a over 0 <= a <= 1: a primal active-set method
** from a = 0.  Outer step: free the bound variable whose gradient most
** wants it inside; inner steps: move toward the minimiser over the free
** set, stopping at the first bound crossed (that variable is bound again),
** until the free minimiser is feasible.  Each outer step lowers the
** objective strictly, so no active set repeats; the cap is a guard. */
static void bounded_qp(const normal *nm, const double *b, double *a)
{
  const int k = nm->k;
  int free_[LW_LAYERS_MAX] = {0};
  for (int j = 0; j < k; j++) a[j] = 0.0;
  for (int outer = 0; outer < 8 * LW_LAYERS_MAX; outer++) {
    int pick = -1;
    double worst = 1e-12;
    for (int j = 0; j < k; j++) {
      if (free_[j]) continue;
      double g = -b[j];
      for (int i = 0; i < k; i++) g += nm->M[j][i] * a[i];
      double want = a[j] == 0.0 ? -g : g; /* > 0: moving inside lowers the objective */
      if (want > worst) {
        worst = want;
        pick = j;
      }
    }
    if (pick < 0) return;
    free_[pick] = 1;
    for (int inner = 0; inner < LW_LAYERS_MAX + 1; inner++) {
      double z[LW_LAYERS_MAX];
      solve_free(nm, b, a, free_, z);
      double step = 1.0;
      int block = -1;
      for (int j = 0; j < k; j++) {
        if (!free_[j] || (z[j] >= 0.0 && z[j] <= 1.0)) continue;
        double bound = z[j] < 0.0 ? 0.0 : 1.0, t = (bound - a[j]) / (z[j] - a[j]);
        if (t < step) {
          step = t;
          block = j;
        }
      }
      for (int j = 0; j < k; j++)
        if (free_[j]) a[j] += step * (z[j] - a[j]);
      if (block < 0) break;
      a[block] = z[block] < 0.0 ? 0.0 : 1.0;
      free_[block] = 0;
    }
  }
}

void lw_layers_separate(const float *r, const float *g, const float *b, size_t n, int k,
                        const unsigned char (*rgb)[3], float *a)
{
  double u[LW_LAYERS_MAX][3];
  normal nm = {.k = k};
  for (int j = 0; j < k; j++)
    for (int c = 0; c < 3; c++) u[j][c] = 1.0 - rgb[j][c] / 255.0;
  for (int i = 0; i < k; i++)
    for (int j = 0; j < k; j++)
      nm.M[i][j] = u[i][0] * u[j][0] + u[i][1] * u[j][1] + u[i][2] * u[j][2] + (i == j ? LW_LAYERS_RIDGE : 0.0);
  /* pixels are independent: threads share them out, the same values */
#pragma omp parallel for schedule(static)
  for (size_t p = 0; p < n; p++) {
    double d[3] = {1.0 - r[p], 1.0 - g[p], 1.0 - b[p]}, rhs[LW_LAYERS_MAX], x[LW_LAYERS_MAX];
    for (int j = 0; j < k; j++) rhs[j] = u[j][0] * d[0] + u[j][1] * d[1] + u[j][2] * d[2] - LW_LAYERS_INK;
    bounded_qp(&nm, rhs, x);
    for (int j = 0; j < k; j++) a[(size_t)j * n + p] = (float)(x[j] < 0.0 ? 0.0 : x[j] > 1.0 ? 1.0 : x[j]);
  }
}
