/*
** schedule.c -- temperature schedules (schedule.h).
**
** Every schedule is a pure function of (parameters, block, previous
** temperature, previous block's statistics) plus one entry in
** lw_schedule_types[]; everything else here works from that table.
*/
#include "linewise/schedule.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"

/* ---- helpers ------------------------------------------------------------ */

/* f = b / (B-1), with b clamped to 0 .. B-1 so that the temperature holds
** after the last block instead of extrapolating (a linear schedule would go
** negative); 0 for B = 1, where the first block is also the last. */
static double block_fraction(const lw_schedule *s, long b)
{
  if (s->blocks <= 1 || b <= 0) return 0.0;
  if (b >= s->blocks - 1) return 1.0;
  return (double)b / (double)(s->blocks - 1);
}

/* x clamped to the closed interval between a and b (either order).  The
** formulas below are exact in real arithmetic; rounding can step a last bit
** outside [t_end, t_start], which would break monotonicity at the ends. */
static double clamp_between(double x, double a, double b)
{
  double lo = a < b ? a : b, hi = a < b ? b : a;
  return x < lo ? lo : x > hi ? hi : x;
}

/* ---- the schedules -------------------------------------------------------- */

static double constant_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  return s->t_start;
}

static double linear_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  double f = block_fraction(s, b);
  /* The last block returns t_end itself: t_start + (t_end - t_start) need
  ** not round to t_end. */
  if (f == 1.0) return s->t_end;
  return clamp_between(s->t_start + (s->t_end - s->t_start) * f, s->t_start, s->t_end);
}

static double geometric_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  double f = block_fraction(s, b);
  if (f == 0.0) return s->t_start;
  if (f == 1.0) return s->t_end;
  double r = s->t_end / s->t_start;
  /* 1e-200 / 1e200 is 0 in a double, and the run quenched from the second
  ** step on; a subnormal ratio has a few bits (1e300 to 7e-24 stepped 16 %
  ** off): such ratios go through their logarithm (the others keep pow, and
  ** the temperatures of runs already made) */
  if (!(r >= DBL_MIN && r <= DBL_MAX))
    return clamp_between(exp(log(s->t_start) + f * (log(s->t_end) - log(s->t_start))), s->t_start, s->t_end);
  return clamp_between(s->t_start * pow(r, f), s->t_start, s->t_end);
}

/* The classical T = T0 / (1 + c ln(1 + b)) cools too slowly to reach any
** given temperature in a fixed number of blocks; c is chosen so that it ends
** at t_end after B blocks: 1 + c ln B = t_start / t_end. */
static double logarithmic_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  if (s->blocks <= 1 || b <= 0) return s->t_start;
  if (b >= s->blocks - 1) return s->t_end;
  double ratio = s->t_start / s->t_end;
  /* a ratio past a double's range made c infinite and T 0 (then t_end):
  ** there 1 + c ln(1+b) is c ln(1+b), and T = t_end ln B / ln(1+b) */
  if (!(ratio <= DBL_MAX))
    return clamp_between(s->t_end * log((double)s->blocks) / log1p((double)b), s->t_start, s->t_end);
  double c = (ratio - 1.0) / log((double)s->blocks);
  return clamp_between(s->t_start / (1.0 + c * log1p((double)b)), s->t_start, s->t_end);
}

/* Huang, Romeo and Sangiovanni-Vincentelli (1986): the step is small where
** the energy fluctuates little relative to T (near a phase transition the
** specific heat sd^2 / T^2 is large and cooling slows).  Without usable
** statistics (first block after a resume without them, a single sample, a
** frozen block with sd = 0, or NaN/inf) the geometric ratio that would reach
** t_end in B blocks keeps the run going.  The result is kept in
** [t_end, t_start], and a NaN (e.g. a NaN t_prev) becomes t_end, so the
** annealer never sees a NaN temperature. */
static double adaptive_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  if (b <= 0) return s->t_start;
  double t;
  if (prev && prev->samples >= 2 && isfinite(prev->sd) && prev->sd > 0)
    t = t_prev * exp(-s->lambda * t_prev / prev->sd);
  else if (s->blocks > 1 && !(s->t_end / s->t_start >= DBL_MIN && s->t_end / s->t_start <= DBL_MAX)) /* as geometric */
    t = t_prev * exp((log(s->t_end) - log(s->t_start)) / (double)(s->blocks - 1));
  else
    t = t_prev * (s->blocks > 1 ? pow(s->t_end / s->t_start, 1.0 / (double)(s->blocks - 1)) : 1.0);
  if (!(t >= s->t_end)) return s->t_end; /* also NaN */
  return t > s->t_start ? s->t_start : t;
}

/* Piecewise linear through the rows, constant outside them. */
static double table_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  size_t n = s->n_table;
  const double *x = s->table_block, *y = s->table_temp;
  if (!n || !x || !y) return 0.0; /* lw_schedule_check rejects this */
  double xb = (double)b;
  if (xb <= x[0]) return y[0];
  if (xb >= x[n - 1]) return y[n - 1];
  size_t lo = 0, hi = n - 1; /* x[lo] <= xb < x[hi] */
  while (hi - lo > 1) {
    size_t mid = lo + (hi - lo) / 2;
    if (x[mid] <= xb) lo = mid;
    else hi = mid;
  }
  return y[lo] + (y[hi] - y[lo]) * ((xb - x[lo]) / (x[hi] - x[lo]));
}

/* ---- the table ------------------------------------------------------------ */

const lw_schedule_type lw_schedule_constant = {
  "constant", "T_b = t_start", LW_SCHEDULE_USES_START, constant_temperature};

const lw_schedule_type lw_schedule_linear = {
  "linear", "T_b = t_start + (t_end - t_start) b/(B-1)",
  LW_SCHEDULE_USES_START | LW_SCHEDULE_USES_END, linear_temperature};

const lw_schedule_type lw_schedule_geometric = {
  "geometric", "T_b = t_start (t_end/t_start)^(b/(B-1))",
  LW_SCHEDULE_USES_START | LW_SCHEDULE_USES_END | LW_SCHEDULE_POSITIVE, geometric_temperature};

const lw_schedule_type lw_schedule_logarithmic = {
  "logarithmic", "T_b = t_start / (1 + c ln(1+b)), c = (t_start/t_end - 1) / ln B",
  LW_SCHEDULE_USES_START | LW_SCHEDULE_USES_END | LW_SCHEDULE_POSITIVE, logarithmic_temperature};

const lw_schedule_type lw_schedule_adaptive = {
  "adaptive",
  "T_b = T_{b-1} exp(-lambda T_{b-1} / sd_{b-1}) within [t_end, t_start] (Huang et al. 1986); "
  "ratio (t_end/t_start)^(1/(B-1)) where sd is 0 or unknown",
  LW_SCHEDULE_USES_START | LW_SCHEDULE_USES_END | LW_SCHEDULE_POSITIVE | LW_SCHEDULE_COOLING |
      LW_SCHEDULE_USES_LAMBDA | LW_SCHEDULE_RECURSIVE,
  adaptive_temperature};

const lw_schedule_type lw_schedule_table = {
  "table", "T_b piecewise linear in b through the file's (step, temperature) rows, held outside them",
  LW_SCHEDULE_USES_TABLE, table_temperature};

const lw_schedule_type *const lw_schedule_types[] = {
  &lw_schedule_constant, &lw_schedule_linear,   &lw_schedule_geometric,
  &lw_schedule_logarithmic, &lw_schedule_adaptive, &lw_schedule_table,
  NULL};

/* ---- generic code: works from the table only ------------------------------ */

const lw_schedule_type *lw_schedule_find(const char *name)
{
  if (!name) return NULL;
  for (const lw_schedule_type *const *t = lw_schedule_types; *t; t++)
    if (!strcmp((*t)->name, name)) return *t;
  return NULL;
}

static char names_buf[512];
static pthread_once_t names_once = PTHREAD_ONCE_INIT;

/* Runs once: the annealer and the docs may ask from several threads. */
static void build_names(void)
{
  size_t used = 0;
  for (const lw_schedule_type *const *t = lw_schedule_types; *t; t++) {
    int n = snprintf(names_buf + used, sizeof names_buf - used, "%s%s", t == lw_schedule_types ? "" : "|",
                     (*t)->name);
    if (n < 0 || (size_t)n >= sizeof names_buf - used) break; /* full: the tests catch this */
    used += (size_t)n;
  }
}

const char *lw_schedule_names(void)
{
  pthread_once(&names_once, build_names);
  return names_buf;
}

/* t_start or t_end: finite and >= 0, or > 0 where the schedule divides by it
** or takes its logarithm. */
static lw_status check_temperature(const char *schedule, const char *key, double v, int positive, lw_error *err)
{
  if (!isfinite(v) || v < 0 || (positive && v == 0))
    return lw_error_set(err, LW_EINPUT, "schedule %s: %s must be a finite number %s, got %g", schedule, key,
                        positive ? "> 0" : ">= 0", v);
  return LW_OK;
}

lw_status lw_schedule_check(const lw_schedule_type *t, const lw_schedule *s, lw_error *err)
{
  if (!t) return lw_error_set(err, LW_EINPUT, "unknown schedule: expected one of %s", lw_schedule_names());
  lw_status st;
  int positive = (t->needs & LW_SCHEDULE_POSITIVE) != 0;
  if (s->blocks < 1)
    return lw_error_set(err, LW_EINPUT, "schedule %s: blocks must be >= 1, got %ld", t->name, s->blocks);
  if ((t->needs & LW_SCHEDULE_USES_START) &&
      (st = check_temperature(t->name, "t_start", s->t_start, positive, err)))
    return st;
  if ((t->needs & LW_SCHEDULE_USES_END) && (st = check_temperature(t->name, "t_end", s->t_end, positive, err)))
    return st;
  if ((t->needs & LW_SCHEDULE_COOLING) && s->t_end > s->t_start)
    return lw_error_set(err, LW_EINPUT, "schedule %s only cools: t_end (%g) must be <= t_start (%g)", t->name,
                        s->t_end, s->t_start);
  if ((t->needs & LW_SCHEDULE_USES_LAMBDA) && !(isfinite(s->lambda) && s->lambda > 0))
    return lw_error_set(err, LW_EINPUT, "schedule %s: lambda must be a finite number > 0, got %g", t->name,
                        s->lambda);
  if ((t->needs & LW_SCHEDULE_USES_TABLE) && (!s->n_table || !s->table_block || !s->table_temp))
    return lw_error_set(err, LW_EINPUT, "schedule %s: no table rows (give a table file)", t->name);
  return LW_OK;
}

void lw_schedule_run(const lw_schedule_type *t, const lw_schedule *s, double *out)
{
  double t_prev = 0.0; /* ignored for b = 0 */
  for (long b = 0; b < s->blocks; b++) t_prev = out[b] = t->temperature(s, b, t_prev, NULL);
}

/* ---- the table file ------------------------------------------------------- */

void lw_schedule_clear(lw_schedule *s)
{
  free(s->table_block);
  free(s->table_temp);
  s->table_block = s->table_temp = NULL;
  s->n_table = 0;
}

/* The whole token as a finite double. */
static int parse_number(const char *tok, double *out) { return lw_number_parse(tok, out); }

/* Splits c (modified) into at most 3 whitespace-separated tokens; returns
** how many there were, 3 meaning "more than two". */
static int split(char *c, char *tok[3])
{
  static const char ws[] = " \t\r\n\v\f";
  int n = 0;
  for (;;) {
    c += strspn(c, ws);
    if (!*c || n == 3) return n;
    tok[n++] = c;
    c += strcspn(c, ws);
    if (*c) *c++ = '\0';
  }
}

lw_status lw_schedule_read_table(lw_schedule *s, const char *path, lw_error *err)
{
  if (lw_text_plain_file(path, err)) return err->code;
  FILE *f = fopen(path, "r");
  if (!f) return lw_error_set(err, LW_EINPUT, "%s: cannot open schedule table: %s", path, strerror(errno));
  char *line = NULL;
  size_t cap = 0, n = 0, rows_cap = 0;
  double *blk = NULL, *tmp = NULL;
  long lineno = 0;
  lw_status status = LW_OK;
  for (;;) {
    long len = lw_text_next_line(f, &line, &cap, &lineno);
    if (len == -2) {
      if (errno == ENOMEM) status = lw_error_set(err, LW_ENOMEM, "%s: out of memory while reading", path);
      else if (ferror(f))
        /* a directory, say: the user named the wrong file, so it is bad input */
        status = lw_error_set(err, LW_EINPUT, "%s:%ld: cannot read schedule table: %s", path, lineno + 1,
                              strerror(errno ? errno : EIO));
      else status = lw_error_set(err, LW_EINPUT, "%s:%ld: " LW_TEXT_NUL_LINE, path, lineno);
    }
    if (len < 0) break;
    const char *cr = strchr(line, '\r'); /* before the comment is cut: "0 10 # hot\r150 1" hid its rows */
    if (cr && cr[strspn(cr, "\r\n")]) { /* CR line ends read as one line of many rows */
      status = lw_error_set(err, LW_EINPUT, "%s:%ld: expected LF or CRLF line ends, got a CR inside the line (a "
                            "file of CR line ends, as old Mac OS wrote)", path, lineno);
      break;
    }
    line[strcspn(line, "#")] = '\0';
    /* the row as shown, cut at a character's start and said cut, and what
    ** it holds unseen (of the whole row: a cut 'é' was "delete it") */
    const char *row = line + strspn(line, " \t");
    char shown[64], hint[96], *tok[3];
    size_t cut = strlen(row);
    if (cut > 56)
      for (cut = 56; cut > 53 && ((unsigned char)row[cut] & 0xC0) == 0x80;) cut--; /* (3 continuation bytes at most) */
    snprintf(shown, sizeof shown, "%.*s%s", (int)cut, row, row[cut] ? "..." : "");
    lw_text_unseen_char(row, hint, sizeof hint);
    int ntok = split(line, tok);
    if (ntok == 0) continue;
    double bv, tv;
    if (ntok != 2) {
      status = lw_error_set(err, LW_EINPUT, "%s:%ld: expected 'step temperature', got '%s'%s", path, lineno, shown,
                            hint);
      break;
    }
    /* Whole numbers only, up to 2^53 where doubles still count every block;
    ** "1.000" is a thousand in a comma locale, not step 1 */
    if (lw_number_separator_hint(tok[0], 1, hint, sizeof hint) || !parse_number(tok[0], &bv) || bv < 0 ||
        bv != floor(bv) || bv > 9007199254740992.0) {
      if (!hint[0]) lw_text_unseen_char(tok[0], hint, sizeof hint);
      status = lw_error_set(err, LW_EINPUT, "%s:%ld: expected a step number (a whole number >= 0), got '%.40s'%s",
                            path, lineno, tok[0], hint);
      break;
    }
    bv += 0.0; /* -0 -> +0 */
    if (n && bv <= blk[n - 1]) {
      status = lw_error_set(err, LW_EINPUT,
                            "%s:%ld: expected a step number greater than the previous row's %.0f, got %.0f", path,
                            lineno, blk[n - 1], bv);
      break;
    }
    /* (the bounds of anneal.t_start and t_end: a row of 1e308 passed them) */
    if (!parse_number(tok[1], &tv) || tv < 0 || tv > 1e300) {
      lw_number_separator_hint(tok[1], 0, hint, sizeof hint);
      if (!hint[0]) lw_text_unseen_char(tok[1], hint, sizeof hint);
      status = lw_error_set(err, LW_EINPUT, "%s:%ld: expected a temperature from 0 to 1e300, got '%.40s'%s",
                            path, lineno, tok[1], hint);
      break;
    }
    if (n == rows_cap) {
      size_t nc = rows_cap ? 2 * rows_cap : 16;
      double *nb = realloc(blk, nc * sizeof *nb);
      if (nb) blk = nb;
      double *nt = nb ? realloc(tmp, nc * sizeof *nt) : NULL;
      if (nt) tmp = nt;
      if (!nb || !nt) {
        status = lw_error_set(err, LW_ENOMEM, "%s:%ld: out of memory for the schedule table", path, lineno);
        break;
      }
      rows_cap = nc;
    }
    blk[n] = bv;
    tmp[n] = tv;
    n++;
  }
  free(line);
  fclose(f);
  if (!status && !n)
    status = lw_error_set(err, LW_EINPUT, "%s:%ld: expected at least one 'step temperature' row, got end of file",
                          path, lineno > 0 ? lineno : 1);
  if (status) {
    free(blk);
    free(tmp);
    return status;
  }
  lw_schedule_clear(s);
  s->table_block = blk;
  s->table_temp = tmp;
  s->n_table = n;
  return LW_OK;
}
