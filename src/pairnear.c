/*
** pairnear.c -- the near field of the pair term (pairnear.h).
**
** lw_pair_segments_exact
** ----------------------
** The double integral of two cubic segments by the geometry of the pair
** (derivation and measurements in docs/NUMERICS.md).  First the closest
** points (s*, t*): the best of a 17 x 17 grid, then Newton (steepest descent
** where the Hessian is not positive definite) projected into the square,
** each step halved until it brings the curves closer.  With d their
** distance, h the larger half-size of the two segments (bounding circles):
**   apart, d / h >= 0.29: Gauss rules of the whole kernel over the whole
**     square, 16 nodes each way, and 24, 32, 48, 64 as d / h falls to
**     0.193, 0.144, 0.096, 0.072 (WHOLE_LO).  The pole of 1/r is then at
**     least d / h half-lengths from each segment, in a Bernstein ellipse
**     rho >= d / h + sqrt(1 + (d / h)^2) beside its middle: error about
**     rho^-2m, 1e-4 at each threshold, the far field's own error at the
**     near zone's edge (docs/NUMERICS.md).  Most near pairs of a drawing,
**     neighbouring lines under an element apart, end here, and 64 x 64
**     kernels cost less than the subdivision that would resolve them;
**   otherwise (crossing, touching, running alongside closer): the
**     subdivision below.
** Each rule is blended into the next closer one by a C2 weight of d / h
** (WHOLE_LO to WHOLE_HI), so the value is a continuous function of the
** control points.
**
** Every part of it is >= 0, as the kernel is: Gauss rules of a non-negative
** kernel, exact integrals of chords, convex blends.  A former singularity
** subtraction (the kernel less 1/r of the tangent lines at the closest
** points) was not: where the curves did not meet, the lines' pole still lay
** inside the square, and the 16 x 16 rule of K - S met -1/|S| beside a node
** pair.  A quench found such a state and drove the energy to -1e8 per pair
** (tests/test_pair.c, exact_integral_is_never_negative).
**
** The subdivision: a piece [t0, t1] of a cubic is again a cubic, with
** control points r(t0), r(t0) + h r'(t0) / 3, r(t1) - h r'(t1) / 3, r(t1)
** (h = t1 - t0), and lies in their convex hull, so in the circle about the
** chord's midpoint through the farthest of them.  A pair of pieces whose
** circles are more than SEP_HI times the larger radius apart takes the 6 x 6
** rule (1/r is analytic in a Bernstein ellipse rho >= 1 + SEP_HI +
** sqrt((1 + SEP_HI)^2 - 1) = 3.07 about each piece: error ~ 1e-6 of the
** pair).  Other pairs are split, A and B in turn (a choice by size would flip
** between two subtrees, whose values differ by their errors), down to a
** leaf, where the pieces' mean chords stand in for them and are integrated
** exactly: each chord moved across itself by its piece's mean distance from
** it, (p1 + p2 - p0 - p3) / 4 of the control points, normal part.  Moving
** a piece to its chord shifts every distance by up to its flatness f; to
** its mean chord, by a deviation of mean zero along the piece, so the first-
** order error cancels along curves alongside (it is left at the pieces'
** ends) and the leaf errs by about (f / d)^2.
** A pair is a leaf when the pieces' flatnesses (each the larger distance of
** its inner control points from its chord) add up to at most FLAT_RATIO of
** the least distance the pieces can have (their chords' distance less the
** flatnesses): this ends curves running alongside at d apart with pieces of
** about sqrt(8 FLAT_RATIO d / curvature) instead of going down to a fixed
** size.  Otherwise a pair is a leaf at LEAF_RATIO of the pair's size: an
** error of order curvature^2 leaf^2 where curves cross, of order the leaf
** where they touch tangentially.
** Each decision is blended too (SEP_LO to SEP_HI, flatness ratios 1 to
** FLAT_BAND, leaf sizes LEAF_BAND to 1).  A piece's 6-node rule is computed
** once and travels with its copies down the tree.
**
** The cutoff: the subdivision integrates (1/r - 1/rc)+ itself.  A pair of
** pieces whose circles lie wholly beyond rc adds nothing (every rule below
** would give 0 there, so it is not split further); the 6 x 6 rule takes the
** cut kernel, kink and all (it is continuous, only its derivative jumps);
** a leaf wholly inside rc takes the mean chords' exact 1/r less their
** lengths' product over rc, clamped at 0 (it is >= 0 wherever the chords
** lie inside the pieces' circles; a mean chord can leave its circle by
** f^2 / length), blended into the cut product rule over one piece size as
** the leaf reaches the cutoff.  A flat leaf is taken only inside the cutoff
** with a piece size to spare (flat leaves can be long, and the blend's
** product rule cannot resolve curves alongside); the tiny leaves keep the
** blend.
*/
#include "linewise/pairnear.h"

#include <math.h>
#include <string.h>

#include "linewise/vec2.h"

typedef lw_v2d v2d;

/* A cubic in power form about a local origin: r(t) = c0 + c1 t + c2 t^2 + c3 t^3. */
typedef struct {
  double x[4], y[4];
} cubic;

static void cubic_from_bezier(const double b[8], double ox, double oy, cubic *c)
{
  double x0 = b[0] - ox, x1 = b[2] - ox, x2 = b[4] - ox, x3 = b[6] - ox;
  double y0 = b[1] - oy, y1 = b[3] - oy, y2 = b[5] - oy, y3 = b[7] - oy;
  c->x[0] = x0;
  c->x[1] = 3.0 * (x1 - x0);
  c->x[2] = 3.0 * (x0 - 2.0 * x1 + x2);
  c->x[3] = x3 - x0 + 3.0 * (x1 - x2);
  c->y[0] = y0;
  c->y[1] = 3.0 * (y1 - y0);
  c->y[2] = 3.0 * (y0 - 2.0 * y1 + y2);
  c->y[3] = y3 - y0 + 3.0 * (y1 - y2);
}

static inline void cubic_eval(const cubic *c, double t, double r[2], double d[2])
{
  r[0] = c->x[0] + t * (c->x[1] + t * (c->x[2] + t * c->x[3]));
  r[1] = c->y[0] + t * (c->y[1] + t * (c->y[2] + t * c->y[3]));
  d[0] = c->x[1] + t * (2.0 * c->x[2] + t * 3.0 * c->x[3]);
  d[1] = c->y[1] + t * (2.0 * c->y[2] + t * 3.0 * c->y[3]);
}

/* A piece [t0, t1] of a cubic: end points and derivatives, and its bounding
** circle (centre, radius). */
typedef struct {
  double t0, t1;
  double r0[2], d0[2], r1[2], d1[2];
  double cx, cy, rad;
  double flat;    /* bound of its distance from its chord (control points) */
  int has_nodes;  /* x, y, w below hold its 6-node rule */
  double x[6], y[6], w[6];
} piece;

static void piece_bound(piece *p)
{
  double h3 = (p->t1 - p->t0) / 3.0;
  double cx = 0.5 * (p->r0[0] + p->r1[0]), cy = 0.5 * (p->r0[1] + p->r1[1]);
  double ex = p->r0[0] - cx, ey = p->r0[1] - cy;
  double rad2 = ex * ex + ey * ey;
  double ax = p->r0[0] + h3 * p->d0[0] - cx, ay = p->r0[1] + h3 * p->d0[1] - cy;
  double bx = p->r1[0] - h3 * p->d1[0] - cx, by = p->r1[1] - h3 * p->d1[1] - cy;
  double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by;
  if (a2 > rad2) rad2 = a2;
  if (b2 > rad2) rad2 = b2;
  p->cx = cx;
  p->cy = cy;
  p->rad = sqrt(rad2);
  /* the curve lies in the hull of its control points, so within the larger
  ** of their two distances from the chord */
  double chx = p->r1[0] - p->r0[0], chy = p->r1[1] - p->r0[1], ch = sqrt(chx * chx + chy * chy);
  double fa = fabs((ax - ex) * chy - (ay - ey) * chx), fb = fabs((bx - ex) * chy - (by - ey) * chx);
  p->flat = ch > 0.0 ? fmax(fa, fb) / ch : 2.0 * p->rad;
  p->has_nodes = 0;
}

static void piece_init(piece *p, const cubic *c, double t0, double t1)
{
  p->t0 = t0;
  p->t1 = t1;
  cubic_eval(c, t0, p->r0, p->d0);
  cubic_eval(c, t1, p->r1, p->d1);
  piece_bound(p);
}

/* Piece [t0, t1] of a cubic from its ends, bound; its nodes not yet computed. */
static void piece_set(piece *p, double t0, double t1, const double r0[2], const double d0[2], const double r1[2],
                      const double d1[2])
{
  p->t0 = t0;
  p->t1 = t1;
  memcpy(p->r0, r0, sizeof p->r0);
  memcpy(p->d0, d0, sizeof p->d0);
  memcpy(p->r1, r1, sizeof p->r1);
  memcpy(p->d1, d1, sizeof p->d1);
  piece_bound(p);
}

/* The halves of piece p, which may be lo itself: only the ends are copied
** (a copy of the whole would carry the node arrays, which no half keeps). */
static void piece_split(const piece *p, const cubic *c, piece *lo, piece *hi)
{
  const double t0 = p->t0, t1 = p->t1, tm = 0.5 * (t0 + t1);
  const double r0[2] = {p->r0[0], p->r0[1]}, d0[2] = {p->d0[0], p->d0[1]};
  const double r1[2] = {p->r1[0], p->r1[1]}, d1[2] = {p->d1[0], p->d1[1]};
  double rm[2], dm[2];
  cubic_eval(c, tm, rm, dm);
  piece_set(lo, t0, tm, r0, d0, rm, dm);
  piece_set(hi, tm, t1, rm, dm, r1, d1);
}

/* Each decision blends from its limit to these times it (SEP_LO to SEP_HI
** for the 6 x 6 rule): a pair in a blend is both taken and split, so narrow
** bands save that double work (from bands of 0.5 to 1 and 1 to 2, 29 % of
** the 6 x 6 rules and 12 % of the leaves, 7 % of X) and take rules and
** leaves only where they are more accurate.  Narrower flatness and leaf
** bands steepen the blends until a central difference at 1e-6 of the
** scale no longer follows X's derivative (tests/test_pairgrad.c).  The
** limits are set, like the whole-square rules', for about 1e-4 of a pair:
** the 6 x 6 rule from 0.7 radius apart (1e-6), flat leaves at 0.15 (of
** second order: (f / d)^2; 0.2 doubles the worst touching pairs' error). */
#define SEP_LO 0.6
#define SEP_HI 0.7
#define LEAF_RATIO 5e-3
#define FLAT_RATIO 0.15
#define LEAF_BAND 1.5
#define FLAT_BAND 1.5
#define STACK_MAX 128

/* Gauss-Legendre on [0, 1]: 6 nodes for pieces, 16 (and 24 to 64 below) for
** whole segments. */
#define GAUSS_S 6
static const double G6_S[GAUSS_S] = {0.033765242898423986, 0.16939530676686774, 0.38069040695840154,
                                     0.61930959304159846, 0.83060469323313226, 0.96623475710157601};
static const double G6_W[GAUSS_S] = {0.085662246189585173, 0.18038078652406930, 0.23395696728634552,
                                     0.23395696728634552, 0.18038078652406930, 0.085662246189585173};
#define GAUSS_L 16
#define GAUSS_MAX 64
static const double G16_S[GAUSS_L] = {
    0.0052995325041750337, 0.027712488463383700, 0.067184398806084122, 0.12229779582249845,
    0.19106187779867811,   0.27099161117138637,  0.35919822461037054,  0.45249374508118123,
    0.54750625491881877,   0.64080177538962946,  0.72900838882861363,  0.80893812220132189,
    0.87770220417750155,   0.93281560119391588,  0.97228751153661630,  0.99470046749582497};
static const double G16_W[GAUSS_L] = {
    0.013576229705877047, 0.031126761969323946, 0.047579255841246392, 0.062314485627766936,
    0.074797994408288366, 0.084578259697501269, 0.091301707522461794, 0.094725305227534249,
    0.094725305227534249, 0.091301707522461794, 0.084578259697501269, 0.074797994408288366,
    0.062314485627766936, 0.047579255841246392, 0.031126761969323946, 0.013576229705877047};

/* 24 to 64 nodes: the whole-square rules for segments closer than the
** 16-node rule resolves (lw_quad_init's nodes, polished to rounding level). */
static const double G24_S[24] = {
    0.00240639000148932, 0.012635722014345251, 0.030862723998633622, 0.056792236497799485,
    0.08999900701304854, 0.12993790421072282, 0.17595317403151223, 0.22728926430558022,
    0.28310324618697741, 0.3424786601519183, 0.40444056626319186, 0.46797155356869719,
    0.53202844643130276, 0.5955594337368082, 0.6575213398480817, 0.71689675381302254,
    0.77271073569441973, 0.82404682596848777, 0.87006209578927718, 0.91000099298695147,
    0.94320776350220048, 0.96913727600136634, 0.98736427798565474, 0.99759360999851066};
static const double G24_W[24] = {
    0.0061706148999936001, 0.014265694314466832, 0.022138719408709904, 0.029649292457718392,
    0.03667324070554015, 0.043095080765976637, 0.048809326052056942, 0.053722135057982817,
    0.0577528340268628, 0.060835236463901696, 0.062918728173414151, 0.06396909767337608,
    0.06396909767337608, 0.062918728173414151, 0.060835236463901696, 0.0577528340268628,
    0.053722135057982817, 0.048809326052056942, 0.043095080765976637, 0.03667324070554015,
    0.029649292457718392, 0.022138719408709904, 0.014265694314466832, 0.0061706148999936001};
static const double G32_S[32] = {
    0.0013680690752592183, 0.0071942442273658326, 0.017618872206246784, 0.032546962031130153,
    0.051839422116973941, 0.075316193133715015, 0.10275810201602879, 0.13390894062985517,
    0.16847786653489241, 0.20614212137961885, 0.24655004553388529, 0.28932436193468231,
    0.33406569885893617, 0.38035631887393145, 0.42776401920860174, 0.47584616715613082,
    0.52415383284386918, 0.57223598079139826, 0.61964368112606849, 0.66593430114106378,
    0.71067563806531764, 0.75344995446611474, 0.79385787862038115, 0.83152213346510762,
    0.86609105937014486, 0.89724189798397125, 0.92468380686628493, 0.9481605778830261,
    0.96745303796886983, 0.98238112779375319, 0.99280575577263419, 0.99863193092474078};
static const double G32_W[32] = {
    0.0035093050047350482, 0.0081371973654528352, 0.012696032654631029, 0.017136931456510716,
    0.021417949011113342, 0.025499029631188087, 0.029342046739267772, 0.032911111388180925,
    0.036172897054424252, 0.039096947893535156, 0.041655962113473374, 0.043826046502201906,
    0.045586939347881945, 0.046922199540402283, 0.04781936003963743, 0.048270044257363899,
    0.048270044257363899, 0.04781936003963743, 0.046922199540402283, 0.045586939347881945,
    0.043826046502201906, 0.041655962113473374, 0.039096947893535156, 0.036172897054424252,
    0.032911111388180925, 0.029342046739267772, 0.025499029631188087, 0.021417949011113342,
    0.017136931456510716, 0.012696032654631029, 0.0081371973654528352, 0.0035093050047350482};
static const double G48_S[48] = {
    0.00061449637378694071, 0.003234913866824621, 0.007937708138586571, 0.014704203726876374,
    0.023506148419784569, 0.034306654646722834, 0.047060431642215163, 0.061713989862876059,
    0.078205869187803229, 0.096466897985278688, 0.11642048374212983, 0.13798293453809268,
    0.16106381018366805, 0.1855663016117432, 0.21138763695801366, 0.23841951263888347,
    0.26654854762452079, 0.29565675900464161, 0.32562205685391965, 0.35631875632227222,
    0.38761810480265546, 0.41938882196555416, 0.45149765039526862, 0.48380991451856531,
    0.51619008548143464, 0.54850234960473132, 0.58061117803444584, 0.61238189519734454,
    0.64368124367772783, 0.67437794314608035, 0.70434324099535839, 0.73345145237547915,
    0.7615804873611165, 0.78861236304198634, 0.81443369838825685, 0.838936189816332,
    0.86201706546190737, 0.88357951625787012, 0.90353310201472137, 0.92179413081219674,
    0.93828601013712398, 0.95293956835778482, 0.96569334535327722, 0.9764938515802154,
    0.98529579627312358, 0.99206229186141348, 0.99676508613317538, 0.99938550362621303};
static const double G48_W[48] = {
    0.0015766730261529192, 0.0036637769506381312, 0.0057386172896172699, 0.0077896578614719244,
    0.0098080802286777645, 0.01178538041966219, 0.013713254854178474, 0.015583613916399045,
    0.017388611282385221, 0.019120675532915354, 0.020772541471732374, 0.02233728042834714,
    0.023808329246245239, 0.025179517776927236, 0.026445094742596834, 0.027599751849992082,
    0.028638646050201607, 0.029557419849197818, 0.03035221958294694, 0.031019711579946332,
    0.03155709614312701, 0.031962119292324093, 0.032233082217975044, 0.032368848406341959,
    0.032368848406341959, 0.032233082217975044, 0.031962119292324093, 0.03155709614312701,
    0.031019711579946332, 0.03035221958294694, 0.029557419849197818, 0.028638646050201607,
    0.027599751849992082, 0.026445094742596834, 0.025179517776927236, 0.023808329246245239,
    0.02233728042834714, 0.020772541471732374, 0.019120675532915354, 0.017388611282385221,
    0.015583613916399045, 0.013713254854178474, 0.01178538041966219, 0.0098080802286777645,
    0.0077896578614719244, 0.0057386172896172699, 0.0036637769506381312, 0.0015766730261529192};
static const double G64_S[64] = {
    0.00034747913211393029, 0.0018299416140223604, 0.00449331426162784, 0.0083318730576870219,
    0.013336586105044517, 0.01949560017397314, 0.026794312570798593, 0.035215413934030215,
    0.044738931460748595, 0.055342277002442944, 0.067000300922953587, 0.079685351873709814,
    0.093367342438601217, 0.10801382052832929, 0.12359004636973406, 0.14005907491419459,
    0.15738184347288336, 0.17551726437267132, 0.19442232241380336, 0.21405217689868297,
    0.23436026799005272, 0.25529842714647349, 0.27681699137326793, 0.29886492101800421,
    0.32138992083116596, 0.34433856400489454, 0.36765641889561629, 0.39128817812999644,
    0.41517778978800357, 0.43926859035193971, 0.46350343910610048, 0.48782485366828776,
    0.51217514633171224, 0.53649656089389952, 0.56073140964806023, 0.58482221021199643,
    0.6087118218700035, 0.63234358110438371, 0.65566143599510551, 0.67861007916883409,
    0.70113507898199579, 0.72318300862673202, 0.74470157285352645, 0.76563973200994728,
    0.78594782310131706, 0.80557767758619658, 0.82448273562732866, 0.84261815652711658,
    0.85994092508580544, 0.87640995363026597, 0.89198617947167069, 0.90663265756139877,
    0.92031464812629016, 0.93299969907704638, 0.94465772299755701, 0.95526106853925141,
    0.96478458606596984, 0.97320568742920144, 0.98050439982602688, 0.98666341389495549,
    0.99166812694231299, 0.9955066857383722, 0.99817005838597761, 0.99965252086788603};
static const double G64_W[64] = {
    0.00089164036084821651, 0.002073516630281234, 0.0032522289844891814, 0.0044233799131819735,
    0.0055840697300655641, 0.0067315239483593213, 0.0078630152380123591, 0.0089758578878486716,
    0.010067411576765104, 0.011135086904191627, 0.012176351284355437, 0.013188734857527329,
    0.014169836307129742, 0.015117328536201239, 0.016028964177425775, 0.016902580918570803,
    0.017736106628441193, 0.018527564270120023, 0.019275076589307813, 0.019976870566360171,
    0.020631281621311764, 0.021236757561826795, 0.021791862264661725, 0.022295279081878283,
    0.022745813963709071, 0.023142398290657208, 0.02348409140810501, 0.023770082857415154,
    0.023999694298229155, 0.024172381117401477, 0.024287733720751714, 0.024345478504569862,
    0.024345478504569862, 0.024287733720751714, 0.024172381117401477, 0.023999694298229155,
    0.023770082857415154, 0.02348409140810501, 0.023142398290657208, 0.022745813963709071,
    0.022295279081878283, 0.021791862264661725, 0.021236757561826795, 0.020631281621311764,
    0.019976870566360171, 0.019275076589307813, 0.018527564270120023, 0.017736106628441193,
    0.016902580918570803, 0.016028964177425775, 0.015117328536201239, 0.014169836307129742,
    0.013188734857527329, 0.012176351284355437, 0.011135086904191627, 0.010067411576765104,
    0.0089758578878486716, 0.0078630152380123591, 0.0067315239483593213, 0.0055840697300655641,
    0.0044233799131819735, 0.0032522289844891814, 0.002073516630281234, 0.00089164036084821651};

/* The whole-square rules, in the order they are tried: m nodes each way for
** segments whose least distance d is at least lo (blended in up to hi) times
** the larger half-size h.  The pole of 1/r is then at least lo half-lengths
** from each segment, in a Bernstein ellipse rho = lo + sqrt(1 + lo^2) beside
** its middle, and the rule errs by about rho^-2m: 1e-4 at lo = sinh(2 ln 10
** / m), about what the product rule errs by at the near zone's edge (the
** thresholds for 1e-5 cost X a tenth more).  Closer pairs take the
** subdivision. */
#define N_WHOLE 5
static const int WHOLE_M[N_WHOLE] = {16, 24, 32, 48, 64};
static const double *const WHOLE_S[N_WHOLE] = {G16_S, G24_S, G32_S, G48_S, G64_S};
static const double *const WHOLE_W[N_WHOLE] = {G16_W, G24_W, G32_W, G48_W, G64_W};
static const double WHOLE_LO[N_WHOLE] = {0.29, 0.193, 0.144, 0.096, 0.072};
static const double WHOLE_HI[N_WHOLE] = {0.3045, 0.20265, 0.1512, 0.1008, 0.0756};

/* Positions and length weights of nodes k0 to m - 1 of an m-node rule on a
** piece. */
static void rule_nodes_from(const cubic *c, double t0, double t1, const double *s, const double *w, int k0, int m,
                            double *x, double *y, double *wt)
{
  double h = t1 - t0, r[2], d[2];
  for (int k = k0; k < m; k++) {
    cubic_eval(c, t0 + h * s[k], r, d);
    x[k] = r[0];
    y[k] = r[1];
    wt[k] = h * w[k] * sqrt(d[0] * d[0] + d[1] * d[1]);
  }
}

#if LW_VEC_HAVE_WIDE
#include <immintrin.h>

/* rule_nodes_from four nodes at a time: each lane by cubic_eval's operations
** in its order (no fused multiply-add), so the same bits.  An m that is not
** a multiple of 4 ends with the last four nodes, some done twice to the same
** bits.  Returns the nodes done: m, or 0 for m < 4. */
__attribute__((target("avx2"))) static int rule_nodes4(const cubic *c, double t0, double t1, const double *s,
                                                       const double *w, int m, double *x, double *y, double *wt)
{
  const double h = t1 - t0;
  const __m256d vt0 = _mm256_set1_pd(t0), vh = _mm256_set1_pd(h), three = _mm256_set1_pd(3.0);
  const __m256d x0 = _mm256_set1_pd(c->x[0]), x1 = _mm256_set1_pd(c->x[1]), x2 = _mm256_set1_pd(c->x[2]);
  const __m256d x3 = _mm256_set1_pd(c->x[3]), x22 = _mm256_set1_pd(2.0 * c->x[2]);
  const __m256d y0 = _mm256_set1_pd(c->y[0]), y1 = _mm256_set1_pd(c->y[1]), y2 = _mm256_set1_pd(c->y[2]);
  const __m256d y3 = _mm256_set1_pd(c->y[3]), y22 = _mm256_set1_pd(2.0 * c->y[2]);
  if (m < 4) return 0;
  for (int next = 0, k = 0; next < m; next = k + 4) {
    k = next + 4 <= m ? next : m - 4;
    const __m256d t = _mm256_add_pd(vt0, _mm256_mul_pd(vh, _mm256_loadu_pd(s + k))), t3 = _mm256_mul_pd(t, three);
    const __m256d rx =
        _mm256_add_pd(x0, _mm256_mul_pd(t, _mm256_add_pd(x1, _mm256_mul_pd(t, _mm256_add_pd(x2, _mm256_mul_pd(t, x3))))));
    const __m256d ry =
        _mm256_add_pd(y0, _mm256_mul_pd(t, _mm256_add_pd(y1, _mm256_mul_pd(t, _mm256_add_pd(y2, _mm256_mul_pd(t, y3))))));
    const __m256d dx = _mm256_add_pd(x1, _mm256_mul_pd(t, _mm256_add_pd(x22, _mm256_mul_pd(t3, x3))));
    const __m256d dy = _mm256_add_pd(y1, _mm256_mul_pd(t, _mm256_add_pd(y22, _mm256_mul_pd(t3, y3))));
    const __m256d sp = _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)));
    _mm256_storeu_pd(x + k, rx);
    _mm256_storeu_pd(y + k, ry);
    _mm256_storeu_pd(wt + k, _mm256_mul_pd(_mm256_mul_pd(vh, _mm256_loadu_pd(w + k)), sp));
  }
  return m;
}
#endif

/* Positions and length weights of an m-node rule on a piece. */
static void rule_nodes(const cubic *c, double t0, double t1, const double *s, const double *w, int m,
                       double *x, double *y, double *wt)
{
  int k0 = 0;
#if LW_VEC_HAVE_WIDE
  if (lw_vec_wide()) k0 = rule_nodes4(c, t0, t1, s, w, m, x, y, wt);
#endif
  rule_nodes_from(c, t0, t1, s, w, k0, m, x, y, wt);
}

typedef enum { KERNEL_INV, KERNEL_CUT } kernel_kind;

/* The product rule's sum over nodes (A's: ax, ay, aw; B's: bx, by, bw) for
** the kernel 1/r (inv = 0, rc2 = inf) or (1/r - 1/rc)+, B's nodes two at a
** time; beyond rc a term is masked to 0 (a comparison gives all ones or 0). */
static double product_sum2(const double *ax, const double *ay, const double *aw, const double *bx,
                           const double *by, const double *bw, int m, kernel_kind kind, double inv, double rc2)
{
  v2d vx[GAUSS_MAX / 2], vy[GAUSS_MAX / 2], vw[GAUSS_MAX / 2], sum = {0.0, 0.0};
  for (int j = 0; j < m / 2; j++) {
    vx[j] = (v2d){bx[2 * j], bx[2 * j + 1]};
    vy[j] = (v2d){by[2 * j], by[2 * j + 1]};
    vw[j] = (v2d){bw[2 * j], bw[2 * j + 1]};
  }
  const v2d vinv = {inv, inv}, vrc2 = {rc2, rc2};
  for (int i = 0; i < m; i++) {
    const v2d x = {ax[i], ax[i]}, y = {ay[i], ay[i]};
    v2d acc = {0.0, 0.0};
    if (kind == KERNEL_INV) {
      for (int j = 0; j < m / 2; j++) {
        v2d dx = x - vx[j], dy = y - vy[j];
        acc += vw[j] / lw_vsqrt2(dx * dx + dy * dy);
      }
    } else {
      for (int j = 0; j < m / 2; j++) {
        v2d dx = x - vx[j], dy = y - vy[j], r2 = dx * dx + dy * dy;
        const lw_v2l in = r2 < vrc2;
        if (!(in[0] | in[1])) continue; /* as product_sum4 */
        v2d q = vw[j] * (1.0 / lw_vsqrt2(r2) - vinv);
        acc += (v2d)((lw_v2l)q & in);
      }
    }
    sum += (v2d){aw[i], aw[i]} * acc;
  }
  return sum[0] + sum[1];
}

#if LW_VEC_HAVE_WIDE

/* product_sum2 four of B's nodes at a time (m a multiple of 4): each lane
** as there, and the lanes of nodes j, j + 1 and then j + 2, j + 3 added to
** the two-lane accumulator in product_sum2's order, so the same bits. */
__attribute__((target("avx2"))) static double product_sum4(const double *ax, const double *ay, const double *aw,
                                                            const double *bx, const double *by, const double *bw,
                                                            int m, kernel_kind kind, double inv, double rc2)
{
  const __m256d vinv = _mm256_set1_pd(inv), vrc2 = _mm256_set1_pd(rc2), one = _mm256_set1_pd(1.0);
  __m128d sum = _mm_setzero_pd();
  for (int i = 0; i < m; i++) {
    const __m256d x = _mm256_set1_pd(ax[i]), y = _mm256_set1_pd(ay[i]);
    __m128d acc = _mm_setzero_pd();
    for (int j = 0; j < m; j += 4) {
      __m256d dx = _mm256_sub_pd(x, _mm256_loadu_pd(bx + j)), dy = _mm256_sub_pd(y, _mm256_loadu_pd(by + j));
      __m256d r2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), w = _mm256_loadu_pd(bw + j), q;
      if (kind == KERNEL_INV) {
        q = _mm256_div_pd(w, _mm256_sqrt_pd(r2));
      } else {
        /* nodes wholly beyond rc add +0, which changes no sum here: skipped
        ** (a third of them; a row meets rc in runs, so unlike the walk's
        ** test, walk.c, this branch is predicted) */
        const __m256d in = _mm256_cmp_pd(r2, vrc2, _CMP_LT_OQ);
        if (!_mm256_movemask_pd(in)) continue;
        q = _mm256_mul_pd(w, _mm256_sub_pd(_mm256_div_pd(one, _mm256_sqrt_pd(r2)), vinv));
        q = _mm256_and_pd(q, in);
      }
      acc = _mm_add_pd(acc, _mm256_castpd256_pd128(q));
      acc = _mm_add_pd(acc, _mm256_extractf128_pd(q, 1));
    }
    sum = _mm_add_pd(sum, _mm_mul_pd(_mm_set1_pd(aw[i]), acc));
  }
  double lanes[2];
  _mm_storeu_pd(lanes, sum);
  return lanes[0] + lanes[1];
}
#endif

/* The product rule of an m-node rule (m a multiple of 4, at most GAUSS_MAX)
** over the whole of two segments, for the kernel 1/r or (1/r - 1/rc)+. */
static double product_rule(const cubic *ca, const cubic *cb, const double *s, const double *w, int m,
                           kernel_kind kind, double rc)
{
  double ax[GAUSS_MAX], ay[GAUSS_MAX], aw[GAUSS_MAX], bx[GAUSS_MAX], by[GAUSS_MAX], bw[GAUSS_MAX];
  rule_nodes(ca, 0.0, 1.0, s, w, m, ax, ay, aw);
  rule_nodes(cb, 0.0, 1.0, s, w, m, bx, by, bw);
  const double inv = rc > 0.0 ? 1.0 / rc : 0.0, rc2 = rc > 0.0 ? rc * rc : INFINITY;
#if LW_VEC_HAVE_WIDE
  if (lw_vec_wide()) return product_sum4(ax, ay, aw, bx, by, bw, m, kind, inv, rc2);
#endif
  return product_sum2(ax, ay, aw, bx, by, bw, m, kind, inv, rc2);
}

/* 0 at x <= 0, 1 at x >= 1, C2 between. */
static inline double smooth_step(double x)
{
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return lw_pair_ramp(x, NULL);
}

/* The 6-node rule of a piece, computed once: copies of the piece on the
** stack carry it. */
static void piece_nodes(const cubic *c, piece *p)
{
  if (p->has_nodes) return;
  rule_nodes(c, p->t0, p->t1, G6_S, G6_W, GAUSS_S, p->x, p->y, p->w);
  p->has_nodes = 1;
}


/* The kernel of the subdivision: 1/r, or (1/r - 1/rc)+ where on. */
typedef struct {
  int on;
  double rc, rc2, inv;
} cut;

#if LW_VEC_HAVE_WIDE
/* piece_rule's sum with B's nodes 0 to 3 in one four-lane vector and 4, 5 in
** a two-lane one, each lane as there and added to the accumulator in its
** order (0, 1, then 2, 3, then 4, 5), so the same bits. */
__attribute__((target("avx2"))) static double piece_sum4(const piece *pa, const piece *pb, const cut *k)
{
  const __m256d bx = _mm256_loadu_pd(pb->x), by = _mm256_loadu_pd(pb->y), bw = _mm256_loadu_pd(pb->w);
  const __m128d bx2 = _mm_loadu_pd(pb->x + 4), by2 = _mm_loadu_pd(pb->y + 4), bw2 = _mm_loadu_pd(pb->w + 4);
  const __m256d inv = _mm256_set1_pd(k->inv), rc2 = _mm256_set1_pd(k->rc2);
  __m128d sum = _mm_setzero_pd();
  for (int i = 0; i < GAUSS_S; i++) {
    const __m256d ax = _mm256_set1_pd(pa->x[i]), ay = _mm256_set1_pd(pa->y[i]);
    const __m256d dx = _mm256_sub_pd(ax, bx), dy = _mm256_sub_pd(ay, by);
    const __m256d r2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    const __m128d dx2 = _mm_sub_pd(_mm256_castpd256_pd128(ax), bx2), dy2 = _mm_sub_pd(_mm256_castpd256_pd128(ay), by2);
    const __m128d r22 = _mm_add_pd(_mm_mul_pd(dx2, dx2), _mm_mul_pd(dy2, dy2));
    const __m256d in = _mm256_cmp_pd(r2, rc2, _CMP_LT_OQ);
    const __m128d in2 = _mm_cmplt_pd(r22, _mm256_castpd256_pd128(rc2));
    /* a row wholly beyond rc adds +0 (as in product_sum4) */
    if (k->on && !_mm256_movemask_pd(in) && !_mm_movemask_pd(in2)) continue;
    __m256d q = _mm256_div_pd(bw, _mm256_sqrt_pd(r2));
    __m128d q2 = _mm_div_pd(bw2, _mm_sqrt_pd(r22));
    if (k->on) {
      q = _mm256_and_pd(_mm256_sub_pd(q, _mm256_mul_pd(bw, inv)), in);
      q2 = _mm_and_pd(_mm_sub_pd(q2, _mm_mul_pd(bw2, _mm256_castpd256_pd128(inv))), in2);
    }
    __m128d acc = _mm_add_pd(_mm_setzero_pd(), _mm256_castpd256_pd128(q));
    acc = _mm_add_pd(_mm_add_pd(acc, _mm256_extractf128_pd(q, 1)), q2);
    sum = _mm_add_pd(sum, _mm_mul_pd(_mm_set1_pd(pa->w[i]), acc));
  }
  double lanes[2];
  _mm_storeu_pd(lanes, sum);
  return lanes[0] + lanes[1];
}
#endif

/* The 6 x 6 product rule over two pieces of the kernel k, B's nodes two at
** a time.  Every term is >= 0. */
static double piece_rule(const cubic *ca, piece *pa, const cubic *cb, piece *pb, const cut *k)
{
  piece_nodes(ca, pa);
  piece_nodes(cb, pb);
#if LW_VEC_HAVE_WIDE
  if (lw_vec_wide()) return piece_sum4(pa, pb, k);
#endif
  v2d bx[GAUSS_S / 2], by[GAUSS_S / 2], bw[GAUSS_S / 2], sum = {0.0, 0.0};
  for (int j = 0; j < GAUSS_S / 2; j++) {
    bx[j] = (v2d){pb->x[2 * j], pb->x[2 * j + 1]};
    by[j] = (v2d){pb->y[2 * j], pb->y[2 * j + 1]};
    bw[j] = (v2d){pb->w[2 * j], pb->w[2 * j + 1]};
  }
  const v2d inv = {k->inv, k->inv}, rc2 = {k->rc2, k->rc2};
  for (int i = 0; i < GAUSS_S; i++) {
    const v2d ax = {pa->x[i], pa->x[i]}, ay = {pa->y[i], pa->y[i]}, aw = {pa->w[i], pa->w[i]};
    v2d acc = {0.0, 0.0};
    for (int j = 0; j < GAUSS_S / 2; j++) {
      v2d dx = ax - bx[j], dy = ay - by[j], r2 = dx * dx + dy * dy, q = bw[j] / lw_vsqrt2(r2);
      /* beyond rc the term is masked to 0 (a comparison gives all ones or 0) */
      if (k->on) q = (v2d)((lw_v2l)(q - bw[j] * inv) & (r2 < rc2));
      acc += q;
    }
    sum += aw * acc;
  }
  return sum[0] + sum[1];
}

/* The chord of a piece moved across itself by the piece's mean distance
** from it, (p1 + p2 - p0 - p3) / 4 for control points p0..p3 (the mean of
** the cubic less the chord's mean), normal part. */
static void mean_chord(const piece *p, double e0[2], double e1[2])
{
  double h3 = (p->t1 - p->t0) / 3.0, ux = p->r1[0] - p->r0[0], uy = p->r1[1] - p->r0[1];
  double ox = 0.25 * (h3 * (p->d0[0] - p->d1[0])), oy = 0.25 * (h3 * (p->d0[1] - p->d1[1]));
  double uu = ux * ux + uy * uy, f = uu > 0.0 ? (ox * ux + oy * uy) / uu : 0.0;
  ox -= f * ux;
  oy -= f * uy;
  e0[0] = p->r0[0] + ox;
  e0[1] = p->r0[1] + oy;
  e1[0] = p->r1[0] + ox;
  e1[1] = p->r1[1] + oy;
}

/* A leaf: the mean chords, integrated exactly; their lengths stand in for
** the arcs (equal to O(leaf^2)).  Chords of curves that touch tangentially end
** to end can overlap by a rounding error, which the exact integral reads as
** +inf; the product rule's interior nodes keep such a leaf finite.
** With the cutoff: where the pieces lie wholly inside it (their farthest
** points closer than rc), 1/r - 1/rc of the chords exactly, clamped at 0
** (see the file comment); where they reach past it, the product rule of
** the cut kernel; C2-blended over one piece
** size below rc, so the value is continuous and never negative. */
static double leaf_value(const cubic *ca, piece *pa, const cubic *cb, piece *pb, const cut *k)
{
  double m = 1.0;
  if (k->on) {
    double dx = pa->cx - pb->cx, dy = pa->cy - pb->cy, big = fmax(pa->rad, pb->rad);
    double far = sqrt(dx * dx + dy * dy) + pa->rad + pb->rad;
    m = big > 0.0 ? smooth_step((k->rc - far) / big) : 0.0;
  }
  double a0[2], a1[2], b0[2], b1[2];
  mean_chord(pa, a0, a1);
  mean_chord(pb, b0, b1);
  double v = m > 0.0 ? lw_pair_segseg(a0, a1, b0, b1) : 0.0;
  if (!(v < INFINITY)) return piece_rule(ca, pa, cb, pb, k);
  if (k->on && m > 0.0) {
    /* the chords' lengths (no hypot: nothing here under- or overflows) */
    double ax = pa->r1[0] - pa->r0[0], ay = pa->r1[1] - pa->r0[1], bx = pb->r1[0] - pb->r0[0],
           by = pb->r1[1] - pb->r0[1];
    double la = sqrt(ax * ax + ay * ay), lb = sqrt(bx * bx + by * by);
    v = fmax(0.0, v - la * lb * k->inv);
  }
  return m < 1.0 ? m * v + (1.0 - m) * piece_rule(ca, pa, cb, pb, k) : v;
}

/* Squared distance of point p from segment [a, b]. */
static double point_segment2(const double p[2], const double a[2], const double b[2])
{
  double ux = b[0] - a[0], uy = b[1] - a[1], px = p[0] - a[0], py = p[1] - a[1];
  double uu = ux * ux + uy * uy, t = uu > 0.0 ? (px * ux + py * uy) / uu : 0.0;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  double dx = px - t * ux, dy = py - t * uy;
  return dx * dx + dy * dy;
}

static inline double min2(double a, double b) { return b < a ? b : a; }

/* Distance between the chords of two pieces (0 where they cross). */
static double chord_distance(const piece *pa, const piece *pb)
{
  double ux = pa->r1[0] - pa->r0[0], uy = pa->r1[1] - pa->r0[1];
  double vx = pb->r1[0] - pb->r0[0], vy = pb->r1[1] - pb->r0[1];
  double s0 = ux * (pb->r0[1] - pa->r0[1]) - uy * (pb->r0[0] - pa->r0[0]);
  double s1 = ux * (pb->r1[1] - pa->r0[1]) - uy * (pb->r1[0] - pa->r0[0]);
  double t0 = vx * (pa->r0[1] - pb->r0[1]) - vy * (pa->r0[0] - pb->r0[0]);
  double t1 = vx * (pa->r1[1] - pb->r0[1]) - vy * (pa->r1[0] - pb->r0[0]);
  if (((s0 < 0.0) != (s1 < 0.0)) && ((t0 < 0.0) != (t1 < 0.0))) return 0.0;
  /* the least of the squares, then one root: sqrt is monotone and
  ** correctly rounded, so the root of the least is the least root */
  double d2 = min2(point_segment2(pa->r0, pb->r0, pb->r1), point_segment2(pa->r1, pb->r0, pb->r1));
  return sqrt(min2(d2, min2(point_segment2(pb->r0, pa->r0, pa->r1), point_segment2(pb->r1, pa->r0, pa->r1))));
}

/* The double integral of the kernel by subdivision (see the file comment),
** times root_rest: the whole-square rules' shares are the caller's. */
static double subdivided(const cubic *ca, const piece *root_a, const cubic *cb, const piece *root_b,
                         double root_rest, const cut *k)
{
  piece sa[STACK_MAX], sb[STACK_MAX];
  double share[STACK_MAX];
  int depth[STACK_MAX];
  sa[0] = *root_a;
  sb[0] = *root_b;
  share[0] = root_rest;
  depth[0] = 0;
  const double leaf = LEAF_RATIO * (root_a->rad + root_b->rad);
  double sum = 0.0;
  int top = 1;
  while (top > 0) {
    top--;
    /* the pair in place on the stack (its nodes, once computed, stay with
    ** it); only the piece that is split is copied out */
    piece *pa = &sa[top], *pb = &sb[top];
    double f = share[top];
    int d = depth[top];
    double dx = pa->cx - pb->cx, dy = pa->cy - pb->cy;
    double big = pa->rad > pb->rad ? pa->rad : pb->rad;
    double gap = sqrt(dx * dx + dy * dy) - pa->rad - pb->rad;
    /* pieces wholly beyond the cutoff: every rule below would give 0 */
    if (k->on && gap >= k->rc) continue;
    double w = big > 0.0 ? smooth_step((gap / big - SEP_LO) / (SEP_HI - SEP_LO)) : 1.0;
    if (w > 0.0) sum += f * w * piece_rule(ca, pa, cb, pb, k);
    f *= 1.0 - w;
    if (f == 0.0) continue;
    w = top + 2 > STACK_MAX ? 1.0 : smooth_step((LEAF_BAND * leaf - big) / ((LEAF_BAND - 1.0) * leaf));
    /* or pieces whose flatnesses are within FLAT_RATIO of the least
    ** distance the curves can have there: the chords' 1/r is within that
    ** share of the curves'.  With the cutoff only pieces inside it, with a
    ** piece size to spare: a flat leaf may be long, and one that reached
    ** past rc would take leaf_value's product rule over a ridge it cannot
    ** resolve (4 % off for lines alongside 0.1 mm apart, rc 2 mm).  The
    ** chords are no farther apart than their midpoints, the circles'
    ** centres: where the flatnesses are too large even for that distance
    ** (with a margin for the roundings), the flat weight is 0 without the
    ** chords' distance, which is most pairs that are split. */
    const double centres = sqrt(dx * dx + dy * dy), flats = pa->flat + pb->flat;
    if (w < 1.0 && flats < FLAT_BAND * FLAT_RATIO * (centres * (1.0 + 1e-12) - flats)) {
      double cd = chord_distance(pa, pb) - pa->flat - pb->flat, inside = 1.0;
      if (k->on) inside = smooth_step((k->rc - (sqrt(dx * dx + dy * dy) + pa->rad + pb->rad)) / big - 1.0);
      if (cd > 0.0 && inside > 0.0)
        w = fmax(w, inside * smooth_step((FLAT_BAND * FLAT_RATIO * cd - pa->flat - pb->flat) /
                                         ((FLAT_BAND - 1.0) * FLAT_RATIO * cd)));
    }
    if (w > 0.0) sum += f * w * leaf_value(ca, pa, cb, pb, k);
    f *= 1.0 - w;
    if (f == 0.0) continue;
    /* split A and B in turn: a choice by size would flip between two
    ** subtrees, whose values differ by their errors */
    if (d % 2 == 0) {
      piece_split(pa, ca, &sa[top], &sa[top + 1]);
      sb[top + 1] = sb[top];
    } else {
      piece_split(pb, cb, &sb[top], &sb[top + 1]);
      sa[top + 1] = sa[top];
    }
    share[top] = share[top + 1] = f;
    depth[top] = depth[top + 1] = d + 1;
    top += 2;
  }
  return sum;
}

/* fmin(1, fmax(0, x)) for the x here, never NaN, without the calls. */
static inline double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* The closest points' grid: CP_GRID + 1 points a segment.  A 9 x 9 grid
** (CP_GRID 8) lost shallow crossings: between its points the ridge of
** near approach ran unseen, Newton went to a minimum on the square's edge,
** and a pair 0.0014 half-sizes apart was taken 0.106 apart, by the 48-node
** rule, 2 % off.  On 20,000 recorded calls 17 x 17 finds every approach
** to within half the distance it reports (9 x 9: 69 did not). */
#define CP_GRID 16

/* The grid's points of A and of B, B's padded to whole four-lane vectors
** with NaN: its q compares false, so a padding lane never wins. */
#define CP_COLS ((CP_GRID + 4) / 4 * 4)
typedef struct {
  double ax[CP_GRID + 1], ay[CP_GRID + 1], bx[CP_COLS], by[CP_COLS];
} cp_points;

static void cp_points_eval(const cubic *ca, const cubic *cb, cp_points *g)
{
  double r[2], d[2];
  for (int k = 0; k <= CP_GRID; k++) {
    cubic_eval(ca, k / (double)CP_GRID, r, d);
    g->ax[k] = r[0];
    g->ay[k] = r[1];
    cubic_eval(cb, k / (double)CP_GRID, r, d);
    g->bx[k] = r[0];
    g->by[k] = r[1];
  }
  for (int k = CP_GRID + 1; k < CP_COLS; k++) g->bx[k] = g->by[k] = NAN;
}

/* The grid's best pair: the first in row-major order with the least
** squared distance, as i * (CP_GRID + 1) + j, and that distance in *best;
** -1 where none is below infinity (NaN never is). */
static int cp_grid_best2(const cp_points *g, double *best)
{
  double low = INFINITY;
  int at = -1;
  for (int i = 0; i <= CP_GRID; i++)
    for (int j = 0; j <= CP_GRID; j++) {
      double dx = g->ax[i] - g->bx[j], dy = g->ay[i] - g->by[j], q = dx * dx + dy * dy;
      if (q < low) low = q, at = i * (CP_GRID + 1) + j;
    }
  *best = low;
  return at;
}

#if LW_VEC_HAVE_WIDE
/* cp_grid_best2 four columns at a time, each q by the same operations (no
** fused multiply-add), so the same bits.  Each lane keeps its column's
** first strict minimum and its row (min_pd keeps the old value where q is
** NaN, as q < low does); the pair is then the least key i * (CP_GRID + 1)
** + j of the columns at the overall minimum, so ties go to the first in
** row-major order as in the scalar loop. */
__attribute__((target("avx2"))) static int cp_grid_best4(const cp_points *g, double *best)
{
  enum { V = CP_COLS / 4 };
  __m256d low[V], row[V];
  for (int c = 0; c < V; c++) low[c] = _mm256_set1_pd(INFINITY), row[c] = _mm256_setzero_pd();
  for (int i = 0; i <= CP_GRID; i++) {
    const __m256d x = _mm256_set1_pd(g->ax[i]), y = _mm256_set1_pd(g->ay[i]), vi = _mm256_set1_pd(i);
    /* unrolled, so that low and row stay in registers (GCC -O2 does not) */
#pragma GCC unroll 8
    for (int c = 0; c < V; c++) {
      __m256d dx = _mm256_sub_pd(x, _mm256_loadu_pd(g->bx + 4 * c));
      __m256d dy = _mm256_sub_pd(y, _mm256_loadu_pd(g->by + 4 * c));
      __m256d q = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
      row[c] = _mm256_blendv_pd(row[c], vi, _mm256_cmp_pd(q, low[c], _CMP_LT_OQ));
      low[c] = _mm256_min_pd(q, low[c]);
    }
  }
  /* no lane of low is NaN, so min_pd is an exact minimum in any order */
  __m256d m = low[0];
  for (int c = 1; c < V; c++) m = _mm256_min_pd(m, low[c]);
  m = _mm256_min_pd(m, _mm256_permute2f128_pd(m, m, 1));
  m = _mm256_min_pd(m, _mm256_permute_pd(m, 5));
  *best = _mm256_cvtsd_f64(m);
  if (!(*best < INFINITY)) return -1;
  const __m256d none = _mm256_set1_pd(INFINITY), n = _mm256_set1_pd(CP_GRID + 1);
  __m256d key = none;
  for (int c = 0; c < V; c++) {
    __m256d k = _mm256_add_pd(_mm256_mul_pd(row[c], n), _mm256_set_pd(4 * c + 3, 4 * c + 2, 4 * c + 1, 4 * c));
    key = _mm256_min_pd(key, _mm256_blendv_pd(none, k, _mm256_cmp_pd(low[c], m, _CMP_EQ_OQ)));
  }
  key = _mm256_min_pd(key, _mm256_permute2f128_pd(key, key, 1));
  key = _mm256_min_pd(key, _mm256_permute_pd(key, 5));
  return (int)_mm256_cvtsd_f64(key);
}
#endif

/* The parameters (s, t) of the closest points of two cubics: the best of
** the grid, then Newton on |a(s) - b(t)|^2 kept inside the square. */
static void closest_points(const cubic *ca, const cubic *cb, double *ps, double *pt)
{
  cp_points g;
  cp_points_eval(ca, cb, &g);
  double best, s = 0.0, t = 0.0;
#if LW_VEC_HAVE_WIDE
  int at = lw_vec_wide() ? cp_grid_best4(&g, &best) : cp_grid_best2(&g, &best);
#else
  int at = cp_grid_best2(&g, &best);
#endif
  if (at >= 0) s = at / (CP_GRID + 1) / (double)CP_GRID, t = at % (CP_GRID + 1) / (double)CP_GRID;
  /* Newton where the Hessian is positive definite, else steepest descent
  ** scaled by the speeds; either step projected into the square and halved
  ** until it brings the curves closer (so the grid's best is never lost).
  ** Each curve's point and first derivative at (s, t) come from the step
  ** that moved there, the second derivative from the power form. */
  double a[2], a1[2], b[2], b1[2];
  cubic_eval(ca, s, a, a1);
  cubic_eval(cb, t, b, b1);
  for (int it = 0; it < 30; it++) {
    const double a2[2] = {2.0 * ca->x[2] + 6.0 * ca->x[3] * s, 2.0 * ca->y[2] + 6.0 * ca->y[3] * s};
    const double b2[2] = {2.0 * cb->x[2] + 6.0 * cb->x[3] * t, 2.0 * cb->y[2] + 6.0 * cb->y[3] * t};
    double D[2] = {a[0] - b[0], a[1] - b[1]};
    double gs = D[0] * a1[0] + D[1] * a1[1], gt = -(D[0] * b1[0] + D[1] * b1[1]);
    double vs = a1[0] * a1[0] + a1[1] * a1[1], vt = b1[0] * b1[0] + b1[1] * b1[1];
    double hss = vs + D[0] * a2[0] + D[1] * a2[1], htt = vt - D[0] * b2[0] - D[1] * b2[1];
    double hst = -(a1[0] * b1[0] + a1[1] * b1[1]);
    double det = hss * htt - hst * hst, ds, dt;
    if (det > 1e-12 * (vs * vt + 1e-300) && hss > 0.0) {
      ds = -(htt * gs - hst * gt) / det;
      dt = -(hss * gt - hst * gs) / det;
    } else {
      ds = vs > 0.0 ? -gs / vs : 0.0;
      dt = vt > 0.0 ? -gt / vt : 0.0;
    }
    int moved = 0;
    for (int half = 0; half < 20 && !moved; half++, ds *= 0.5, dt *= 0.5) {
      double ns = clamp01(s + ds), nt = clamp01(t + dt), r[2], r1[2], q[2], q1[2];
      if (ns == s && nt == t) break;
      cubic_eval(ca, ns, r, r1);
      cubic_eval(cb, nt, q, q1);
      double f = (r[0] - q[0]) * (r[0] - q[0]) + (r[1] - q[1]) * (r[1] - q[1]);
      if (f < best) {
        best = f;
        s = ns;
        t = nt;
        memcpy(a, r, sizeof a);
        memcpy(a1, r1, sizeof a1);
        memcpy(b, q, sizeof b);
        memcpy(b1, q1, sizeof b1);
        moved = 1;
      }
    }
    if (!moved) break;
  }
  *ps = s;
  *pt = t;
}

const lw_pairnear_consts lw_pairnear_k = {SEP_LO,  SEP_HI,  LEAF_RATIO, FLAT_RATIO, LEAF_BAND, FLAT_BAND,
                                          STACK_MAX, CP_GRID, G6_S,      G6_W,       GAUSS_S,   N_WHOLE,
                                          WHOLE_M, WHOLE_S, WHOLE_W,   WHOLE_LO,   WHOLE_HI};

double lw_pair_segments_exact(const double a[8], const double b[8], double cutoff)
{
  cubic ca, cb;
  /* a local origin keeps the power form's coefficients small */
  double ox = 0.25 * (a[0] + a[6] + b[0] + b[6]), oy = 0.25 * (a[1] + a[7] + b[1] + b[7]);
  cubic_from_bezier(a, ox, oy, &ca);
  cubic_from_bezier(b, ox, oy, &cb);
  piece pa, pb;
  piece_init(&pa, &ca, 0.0, 1.0);
  piece_init(&pb, &cb, 0.0, 1.0);
  double ss, ts, ra[2], a1[2], rb[2], b1[2];
  closest_points(&ca, &cb, &ss, &ts);
  cubic_eval(&ca, ss, ra, a1);
  cubic_eval(&cb, ts, rb, b1);
  /* The whole-square rules, each blended into the next closer one by a C2
  ** weight of the distance (the least over the segments, a continuous
  ** function of them wherever Newton lands): most near pairs of a drawing,
  ** neighbouring lines under an element apart, end there. */
  const double ex = ra[0] - rb[0], ey = ra[1] - rb[1];
  double half = fmax(pa.rad, pb.rad), dist = sqrt(ex * ex + ey * ey);
  kernel_kind whole = cutoff > 0.0 ? KERNEL_CUT : KERNEL_INV;
  double v = 0.0, rest = 1.0;
  for (int r = 0; r < N_WHOLE && rest > 0.0; r++) {
    double w = half > 0.0 ? smooth_step((dist / half - WHOLE_LO[r]) / (WHOLE_HI[r] - WHOLE_LO[r])) : 1.0;
    if (w > 0.0) v += rest * w * product_rule(&ca, &cb, WHOLE_S[r], WHOLE_W[r], WHOLE_M[r], whole, cutoff);
    rest *= 1.0 - w;
  }
  if (rest > 0.0) {
    const cut k = {cutoff > 0.0, cutoff, cutoff * cutoff, cutoff > 0.0 ? 1.0 / cutoff : 0.0};
    v += subdivided(&ca, &pa, &cb, &pb, rest, &k);
  }
  return v;
}

/* 1 below half the radius, 0 from the radius on, C2 in between. */
static inline double near_weight(double u)
{
  if (u >= 1.0) return 0.0;
  if (u <= 0.5) return 1.0;
  return lw_pair_ramp(2.0 * (1.0 - u), NULL);
}

int lw_pair_bezier_before(const double a[8], const double b[8])
{
  for (int k = 0; k < 8; k++)
    if (a[k] != b[k]) return a[k] < b[k];
  return 1;
}

double lw_pair_order_weight(const double a[8], const double b[8], double dwa[8], double dwb[8])
{
  if (dwa) memset(dwa, 0, 8 * sizeof *dwa);
  if (dwb) memset(dwb, 0, 8 * sizeof *dwb);
  const double ax = a[6] - a[0], ay = a[7] - a[1], bx = b[6] - b[0], by = b[7] - b[1];
  const double band = LW_PAIR_ORDER_BAND * (fabs(ax) + fabs(ay) + fabs(bx) + fabs(by));
  const double gap = b[0] - a[0]; /* >= 0 in this order */
  if (!(gap < band)) return 1.0;
  double dr;
  const double x = gap / band, w = 0.5 + 0.5 * lw_pair_ramp(x, &dr);
  if (dwa && dwb) {
    /* x = gap / band */
    const double dwdx = 0.5 * dr, dgap = dwdx / band, dband = -dwdx * x / band;
    const double s = LW_PAIR_ORDER_BAND * dband;
    dwb[0] += dgap;
    dwa[0] -= dgap;
    dwa[6] += s * (ax > 0) - s * (ax < 0), dwa[0] -= s * (ax > 0) - s * (ax < 0);
    dwa[7] += s * (ay > 0) - s * (ay < 0), dwa[1] -= s * (ay > 0) - s * (ay < 0);
    dwb[6] += s * (bx > 0) - s * (bx < 0), dwb[0] -= s * (bx > 0) - s * (bx < 0);
    dwb[7] += s * (by > 0) - s * (by < 0), dwb[1] -= s * (by > 0) - s * (by < 0);
  }
  return w;
}

/* X_AB of a pair in lw_pair_bezier_before's order, both orders blended in
** the band (pairnear.h). */
static double ordered_exact(const double a[8], const double b[8], double cutoff)
{
  const double w = lw_pair_order_weight(a, b, NULL, NULL), x = lw_pair_segments_exact(a, b, cutoff);
  return w == 1.0 ? x : w * x + (1.0 - w) * lw_pair_segments_exact(b, a, cutoff);
}

/* What lw_pair_near_correction sums over the sample pairs: the largest
** near weight, and the product rule's terms of the near and the far pairs. */
typedef struct {
  double W, near, far;
} near_sums;

/* Sample p against B's samples j0 to j1 - 1, added to *ns in order. */
static void near_row(const lw_pair_sample *p, const lw_pair_sample *sb, int j0, int j1, const lw_pair_ctx *ctx,
                     near_sums *ns)
{
  const double cut2 = ctx->cutoff2, inv = ctx->inv_cutoff;
  for (int j = j0; j < j1; j++) {
    double dx = p->x - sb[j].x, dy = p->y - sb[j].y, r2 = dx * dx + dy * dy;
    double rho2 = lw_pair_near_radius2(ctx, p->dl, sb[j].dl);
    /* a sample without length weighs nothing, even at r = 0 (0 * inf) */
    int weighs = p->dl != 0.0f && sb[j].dl != 0.0f;
    double k = weighs && r2 < cut2 ? (double)p->dl * (double)sb[j].dl * (1.0 / sqrt(r2) - inv) : 0.0;
    if (r2 < rho2) {
      double w = near_weight(sqrt(r2 / rho2));
      if (w > ns->W) ns->W = w;
      ns->near += k;
    } else {
      ns->far += k;
    }
  }
}

#if LW_VEC_HAVE_WIDE
/* near_row over all of A's samples, B's four at a time: each lane's kernel,
** near radius and weight by near_row's operations, then the terms added to
** near and far one by one in near_row's order (the other sum takes +0, which
** changes no sum here: every term is >= 0), so the same bits; the largest
** weight is exact in any order. */
__attribute__((target("avx2"))) static void near_sums4(const lw_pair_sample *sa, const lw_pair_sample *sb, int n,
                                                        const lw_pair_ctx *ctx, near_sums *ns)
{
  double bx[LW_QUAD_MAX], by[LW_QUAD_MAX], bdl[LW_QUAD_MAX];
  for (int j = 0; j < n; j++) bx[j] = sb[j].x, by[j] = sb[j].y, bdl[j] = sb[j].dl;
  const int n4 = n / 4 * 4;
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
  const __m256d cut2 = _mm256_set1_pd(ctx->cutoff2), inv = _mm256_set1_pd(ctx->inv_cutoff);
  const __m256d scale = _mm256_set1_pd(ctx->near_scale), rc = _mm256_set1_pd(ctx->cutoff);
  const __m256d clip = ctx->cutoff > 0.0 ? _mm256_castsi256_pd(_mm256_set1_epi64x(-1)) : zero;
  for (int i = 0; i < n; i++) {
    const __m256d ax = _mm256_set1_pd(sa[i].x), ay = _mm256_set1_pd(sa[i].y), adl = _mm256_set1_pd(sa[i].dl);
    const __m256d a_weighs = _mm256_cmp_pd(adl, zero, _CMP_NEQ_OQ);
    for (int j = 0; j < n4; j += 4) {
      const __m256d dx = _mm256_sub_pd(ax, _mm256_loadu_pd(bx + j)), dy = _mm256_sub_pd(ay, _mm256_loadu_pd(by + j));
      const __m256d r2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), dl = _mm256_loadu_pd(bdl + j);
      /* lw_pair_near_radius2: the larger weight (exact as floats or as
      ** doubles) times the scale, clipped to rc */
      __m256d r = _mm256_mul_pd(scale, _mm256_max_pd(adl, dl));
      r = _mm256_blendv_pd(r, rc, _mm256_and_pd(clip, _mm256_cmp_pd(r, rc, _CMP_GT_OQ)));
      const __m256d rho2 = _mm256_mul_pd(r, r);
      const __m256d use = _mm256_and_pd(_mm256_and_pd(a_weighs, _mm256_cmp_pd(dl, zero, _CMP_NEQ_OQ)),
                                        _mm256_cmp_pd(r2, cut2, _CMP_LT_OQ));
      const __m256d k = _mm256_and_pd(
          use, _mm256_mul_pd(_mm256_mul_pd(adl, dl), _mm256_sub_pd(_mm256_div_pd(one, _mm256_sqrt_pd(r2)), inv)));
      const __m256d is_near = _mm256_cmp_pd(r2, rho2, _CMP_LT_OQ);
      if (_mm256_movemask_pd(is_near)) {
        /* near_weight(sqrt(r2 / rho2)) where near: 1 to u = 0.5, 0 from 1
        ** (lw_pair_ramp's operations, lane by lane) */
        const __m256d u = _mm256_sqrt_pd(_mm256_div_pd(r2, rho2));
        const __m256d t = _mm256_mul_pd(_mm256_set1_pd(2.0), _mm256_sub_pd(one, u));
        const __m256d poly = _mm256_add_pd(_mm256_set1_pd(10.0),
                                           _mm256_mul_pd(t, _mm256_sub_pd(_mm256_mul_pd(_mm256_set1_pd(6.0), t),
                                                                          _mm256_set1_pd(15.0))));
        __m256d w = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(t, t), t), poly);
        w = _mm256_blendv_pd(w, one, _mm256_cmp_pd(u, half, _CMP_LE_OQ));
        w = _mm256_and_pd(w, _mm256_and_pd(is_near, _mm256_cmp_pd(u, one, _CMP_LT_OQ)));
        __m256d m = _mm256_max_pd(w, _mm256_permute2f128_pd(w, w, 1));
        m = _mm256_max_pd(m, _mm256_permute_pd(m, 5));
        const double wm = _mm256_cvtsd_f64(m);
        if (wm > ns->W) ns->W = wm;
      }
      double kn[4], kf[4];
      _mm256_storeu_pd(kn, _mm256_and_pd(is_near, k));
      _mm256_storeu_pd(kf, _mm256_andnot_pd(is_near, k));
      for (int l = 0; l < 4; l++) ns->near += kn[l], ns->far += kf[l];
    }
    near_row(&sa[i], sb, n4, n, ctx, ns);
  }
}
#endif

double lw_pair_near_correction(const double a[8], const lw_pair_sample *sa, const double b[8],
                               const lw_pair_sample *sb, int n, const lw_pair_ctx *ctx)
{
  /* one order for the two segments, so that the value is bitwise symmetric */
  if (!lw_pair_bezier_before(a, b)) {
    const double *t = a;
    const lw_pair_sample *u = sa;
    a = b;
    b = t;
    sa = sb;
    sb = u;
  }
  near_sums ns = {0.0, 0.0, 0.0};
#if LW_VEC_HAVE_WIDE
  if (lw_vec_wide()) near_sums4(sa, sb, n, ctx, &ns);
  else
#endif
    for (int i = 0; i < n; i++) near_row(&sa[i], sb, 0, n, ctx, &ns);
  const double W = ns.W, far = ns.far, near = ns.near;
  /* near pairs with W = 0 lie at the near radius itself (u rounds to 1):
  ** their product-rule terms, which the walk left out (0 dropped them) */
  if (W == 0.0) return near;
  double e = W * ordered_exact(a, b, ctx->cutoff);
  if (W < 1.0) e += (1.0 - W) * (near + far);
  return e - far;
}
