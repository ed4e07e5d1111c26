/*
 * mtcore.h - the one contract between the C kernels of motiontheater and Python.
 *
 * Layout.  Every array is C-contiguous and viewed as (outer, n, inner): the
 * filtered axis has length n, `outer` is the product of the axes before it and
 * `inner` the product of the axes after it.  Sample (o, t, i) of such an array
 * is at p[(o * n + t) * inner + i].  A motion (frames, channels) filtered along
 * its frames is the case outer = 1, n = frames, inner = channels.
 *
 * Ownership.  The caller allocates every input and output; the kernels allocate
 * only small scratch buffers, which they free before returning.  Outputs never
 * alias inputs.  Kernels keep no state between calls and are re-entrant (cffi
 * releases the GIL around every call).
 *
 * Status.  Every mt_* function returns MT_OK (0) or a negative MT_E* code and
 * never prints, aborts or exits.  mt_strerror() names a code.
 *
 * The region between the MT_CDEF markers is read by the cffi build
 * (src/cffi_build.py): it must stay plain declarations and enums.
 */
#ifndef MTCORE_H
#define MTCORE_H

#include <stddef.h>
#include <stdint.h>

/* MT_CDEF_BEGIN */
enum mt_status {
    MT_OK = 0,
    MT_EINVAL = -1, /* an argument is outside its documented range */
    MT_ENOMEM = -2, /* scratch memory could not be allocated */
    MT_EDTYPE = -3, /* the element type code is not one of mt_dtype */
    /* text scanning (mt_scan_frames); the report says where and what */
    MT_ESYNTAX = -4,    /* a token that is not a number where a number belongs */
    MT_ECOUNT = -5,     /* a line holds more or fewer numbers than its key takes */
    MT_EUNKNOWN = -6,   /* a line starts with a key that is not in the table */
    MT_EDUPLICATE = -7, /* a key appears twice in one frame */
    MT_EMISSING = -8,   /* a frame lacks a key that takes numbers */
    MT_EFRAME = -9,     /* a frame number out of sequence, or a key line before any frame */
    MT_ERANGE = -10,    /* more frames than the output holds, or an output buffer too small */
    MT_EFRAMERANGE = -11, /* a frame number outside 0 .. MT_FRAME_MAX, read or to be written */
    MT_EIO = -12          /* a memory-mapped file shrank while it was read (see mt_guard_install) */
};

enum mt_dtype {
    MT_FLOAT32 = 0,
    MT_FLOAT64 = 1
};

/*
 * How a line is extended past its ends, for the line a b c d and the fill
 * value k (the five modes of scipy.ndimage).  An extension longer than the
 * line repeats the pattern.
 *
 *   reflect   d c b a | a b c d | d c b a
 *   nearest   a a a a | a b c d | d d d d
 *   mirror      d c b | a b c d | c b a
 *   constant  k k k k | a b c d | k k k k
 *   wrap      a b c d | a b c d | a b c d
 */
enum mt_mode {
    MT_MODE_REFLECT = 0,
    MT_MODE_NEAREST = 1,
    MT_MODE_MIRROR = 2,
    MT_MODE_CONSTANT = 3,
    MT_MODE_WRAP = 4
};

enum mt_filter {
    MT_FILTER_MEDIAN = 0,   /* element of rank size/2 of the window; NaN if the window holds NaN */
    MT_FILTER_UNIFORM = 1,  /* mean of the window */
    MT_FILTER_CORRELATE = 2 /* sum of weights[j] * window[j] */
};

const char *mt_strerror(int status);

/*
 * Reading memory-mapped files safely: a file truncated while it is mapped
 * and read raises SIGBUS past its new end, which kills the process.  After
 * mt_guard_install() (once per process; it keeps any handler there was for
 * a SIGBUS elsewhere), the scanners (mt_scan_frames, mt_scan_table) and
 * mt_copy_mapped return MT_EIO instead.
 */
int mt_guard_install(void);

/* Copies n bytes of a mapping to target; MT_EIO where the mapping's file has shrunk. */
int mt_copy_mapped(const char *source, size_t n, char *target);

/*
 * One-dimensional filter along the middle axis of (outer, n, inner) arrays of
 * element type `dtype`.  Output sample t is computed from the window of input
 * samples t - size/2 - origin + j, j = 0 .. size-1, extended by `mode` with
 * fill value `cval`.  Only output frames begin .. end-1 of every line are
 * written (0 and n for all of them), so that separate calls on disjoint
 * ranges can share one output from several threads; a range that begins at
 * a multiple of mt_filter1d_block(size) gives, bit for bit, what one call
 * over all frames gives there (the running sums of the uniform filter
 * restart at those multiples).  Requires
 * begin <= end <= n, 1 <= size <= PTRDIFF_MAX / 4 and
 * -(size/2) <= origin <= (size-1)/2; `weights` (size doubles) is read only by
 * MT_FILTER_CORRELATE and may be NULL otherwise; an array of more than
 * PTRDIFF_MAX bytes is MT_EINVAL.  Means and weighted sums are
 * accumulated in double for float32 data; a NaN or an infinity reaches only
 * the outputs whose windows hold it.  The median and the mean of a window
 * longer than the line (size > n) take time and scratch memory in
 * proportion to n, whatever the size; MT_FILTER_CORRELATE reads all size
 * weights for each output and needs scratch for 2 size row pointers
 * (MT_ENOMEM when that cannot be allocated, never a short buffer).
 */
int mt_filter1d(int filter, int dtype, const void *in, void *out,
                size_t outer, size_t n, size_t inner, size_t begin, size_t end,
                size_t size, ptrdiff_t origin, int mode, double cval,
                const double *weights);

/* The block length, in frames, of mt_filter1d for a window of `size`. */
size_t mt_filter1d_block(size_t size);

/*
 * Numbers in text, read and written (number.c, scan.c, format.c), one grammar everywhere:
 *
 *     number  = [sign] (decimal | "inf" | "infinity" | "nan")     words in any case
 *     decimal = (digits ["." [digits]] | "." digits) [("e" | "E") [sign] digits]
 *     sign    = "+" | "-"
 *
 * A number reads as the double nearest it (ties to even), for any count of digits: what
 * Python's float() gives for the same token.  No hexadecimal, '_', "nan(...)" or blanks.
 * Reading and writing never depend on the C locale (LC_NUMERIC).
 */

/* The token text[0 .. len-1] (no blanks around it) into *value; MT_ESYNTAX if it is not a number. */
int mt_parse_number(const char *text, size_t len, double *value);

/* Frame numbers, read and written, are 0 .. MT_FRAME_MAX (18 digits). */
#define MT_FRAME_MAX 999999999999999999

/*
 * Frame text: frames of key lines, each frame opened by a line holding only
 * its frame number (consecutive, from any start), e.g.
 *
 *     1
 *     root 9.37 17.87 -17.32 -2.02 -7.60 -3.23
 *     ltibia 20.088
 *
 * Key i is the byte string keys[i] of key_lens[i] bytes; the counts[i]
 * numbers of its line go to columns offsets[i] .. offsets[i]+counts[i]-1 of
 * the frame's row of `channels` values.  Keys may come in any order within a
 * frame, each at most once; every key with counts[i] > 0 must be present.
 * Lines end in LF, CRLF or CR; blank lines and lines starting with '#' are
 * skipped; tokens are separated by spaces or tabs.  A line of digits only is a
 * frame number; above MT_FRAME_MAX it is MT_EFRAMERANGE.
 */
struct mt_scan_report {
    size_t frames;         /* frames stored */
    long long first_frame; /* number of the first frame */
    size_t line;           /* line of the problem, 1 at the start of the text */
    size_t offset;         /* byte offset of the start of that line */
    long long key;         /* key of the problem, or -1 */
    long long found;       /* numbers found (MT_ECOUNT) or frame number found (MT_EFRAME) */
    long long expected;    /* numbers or frame number expected */
};

/* Scans frame text into values (max_frames x channels, row-major). */
int mt_scan_frames(const char *text, size_t len, const char *const *keys, const size_t *key_lens,
                   const size_t *offsets, const size_t *counts, size_t nkeys, double *values,
                   size_t max_frames, size_t channels, struct mt_scan_report *report);

/*
 * A table of numbers (the MOTION section of a BVH file): `rows` lines of
 * exactly `columns` numbers each, separated by spaces or tabs, into values
 * (rows x columns).  Blank lines are skipped; lines end in LF, CRLF or CR.
 * MT_ECOUNT for a line with more or fewer numbers (report->found and
 * ->expected), MT_ESYNTAX for a token that is not a number, MT_EMISSING for
 * fewer lines than rows, MT_ERANGE for more (report->frames counts rows read).
 */
int mt_scan_table(const char *text, size_t len, size_t rows, size_t columns, double *values,
                  struct mt_scan_report *report);

enum mt_newline {
    MT_NEWLINE_LF = 0,
    MT_NEWLINE_CRLF = 1,
    MT_NEWLINE_CR = 2
};

/*
 * How a text is laid out, so that what is written from it looks the same (style.c):
 *
 *   lf, crlf, cr     its line ends of each kind (a CR followed by LF is one CRLF).
 *   exponent_digits  the fewest digits of its exponents: an exponent is 'e' or 'E' right
 *                    after a digit or '.', then a sign and digits.  The first written with
 *                    a leading zero in two or more digits gives its count (1.23246e-013:
 *                    3; at most 3); else 1 where one has a single digit (1e-5); else 2.
 *   frame_line       the offset of its first line of digits only (blanks around them
 *                    allowed): a frame-number line; -1 for none.
 *   frame_newline    that line's ending (enum mt_newline), -1 where the text ends there.
 */
struct mt_text_style {
    size_t lf;
    size_t crlf;
    size_t cr;
    int exponent_digits;
    long long frame_line;
    int frame_newline;
};

/* The style of text[0 .. len-1]; MT_EIO where it is a mapping whose file has shrunk. */
int mt_text_style(const char *text, size_t len, struct mt_text_style *style);

/*
 * How numbers and lines are written; a NULL style is {0, 2, MT_NEWLINE_LF, MT_NEWLINE_LF}.
 *
 *   digits           0: the shortest text that reads back as exactly the value, of
 *                    those the nearest to it (the digits of Python's repr); exponent
 *                    form below 1e-4 and from 1e16 up, as repr.  1 .. 17: the value
 *                    correctly rounded to that many significant digits (ties to even),
 *                    as C's %.<digits>g: exponent form below 1e-4 and from 10^digits up.
 *                    Trailing zeros and a trailing point are dropped: 17.8693, 3, -0,
 *                    1.23246e-13, -nan, inf (a NaN keeps its sign, not its payload).
 *   exponent_digits  the fewest digits of an exponent, 1 .. 3: 2 gives 1e-05 (Python,
 *                    C on Linux), 3 gives 1e-005 (HDM05 files, C on Windows).
 *   newline          the line ending of mt_format_frames and mt_format_table.
 *   frame_newline    the ending of the lines that hold only a frame number
 *                    (mt_format_frames): HDM05 ends those in LF, every other in CRLF.
 */
struct mt_format_style {
    int digits;
    int exponent_digits;
    int newline;
    int frame_newline;
};

/*
 * The code that writes the shortest texts (style digits 0) of mt_format_frames and
 * mt_format_table, their `code` argument: portable C, or code written by hand for the vector
 * registers of x86-64 processors, AVX2 (the x86-64-v3 level: AVX2, BMI1, BMI2, FMA, LZCNT,
 * MOVBE, F16C) or AVX-512 (x86-64-v4: v3 and AVX-512 F, BW, CD, DQ, VL).  Every code writes the
 * same bytes; MT_NUMBER_CODE_BEST is the one mt_number_code() names, and the others are there
 * for the tests and benchmarks that compare the codes on one processor.  A code the processor
 * does not run is refused (MT_EINVAL).  Texts rounded to digits are the portable code's alone.
 */
enum mt_number_code {
    MT_NUMBER_CODE_BEST = 0,
    MT_NUMBER_CODE_PORTABLE = 1,
    MT_NUMBER_CODE_AVX2 = 2,
    MT_NUMBER_CODE_AVX512 = 3
};

/* The code that MT_NUMBER_CODE_BEST stands for on this processor: the widest it runs. */
int mt_number_code(void);

/* 1 if this processor runs `code` (MT_NUMBER_CODE_BEST and _PORTABLE: always), else 0 (also for a
   value that is none of enum mt_number_code). */
int mt_number_code_runs(int code);

/* Bytes a number can take: -1.2345678901234567e-308. */
enum { MT_NUMBER_MAX = 24 };

/* Writes the text of value into buf (MT_NUMBER_MAX bytes, not NUL-terminated); its length to *written. */
int mt_format_double(double value, const struct mt_format_style *style, char *buf, size_t *written);

/*
 * Writes frames first .. first+frames-1 of values (frames x channels) as
 * frame text, the keys in the order given, into buf of cap bytes; *written
 * receives the length; `code` (enum mt_number_code) writes the shortest texts.  MT_ERANGE if
 * cap is below mt_format_bound(); MT_EFRAMERANGE if a frame number would be outside
 * 0 .. MT_FRAME_MAX.
 */
int mt_format_frames(const double *values, size_t frames, size_t channels, long long first_frame,
                     const char *const *keys, const size_t *key_lens, const size_t *offsets,
                     const size_t *counts, size_t nkeys, const struct mt_format_style *style, int code,
                     char *buf, size_t cap, size_t *written);

/* Bytes that mt_format_frames may need for `frames` frames of these keys (SIZE_MAX past size_t). */
size_t mt_format_bound(size_t frames, const size_t *key_lens, const size_t *counts, size_t nkeys,
                       const struct mt_format_style *style);

/* Writes values (rows x columns) as lines of numbers separated by a blank, the shortest texts by
   `code` (enum mt_number_code); MT_ERANGE if cap is below mt_format_table_bound(). */
int mt_format_table(const double *values, size_t rows, size_t columns, const struct mt_format_style *style,
                    int code, char *buf, size_t cap, size_t *written);

/* Bytes that mt_format_table may need (SIZE_MAX past size_t). */
size_t mt_format_table_bound(size_t rows, size_t columns, const struct mt_format_style *style);

/* Channels of a joint: rotations about, and translations along, its x, y, z; and stretch. */
enum mt_dof {
    MT_DOF_RX = 0,
    MT_DOF_RY = 1,
    MT_DOF_RZ = 2,
    MT_DOF_TX = 3,
    MT_DOF_TY = 4,
    MT_DOF_TZ = 5,
    MT_DOF_L = 6 /* translation along the bone's direction */
};

/*
 * Forward kinematics of a tree of joints over frames, ASF/AMC semantics.
 *
 * Joint j has parent[j] (-1 for a root); order[] lists every joint once,
 * each after its parent.  Its rest data: axis[9j..] the orthonormal frame C
 * of its channels (row-major), direction[3j..] its unit direction and
 * segment[3j..] its bone vector (direction times length; for a root, its
 * rest position).  Its channels are dof_kind[c] at column dof_column[c] of
 * a frame's row of `channels` values, for c = dof_start[j] .. dof_start[j+1]-1.
 *
 * Per frame: M is the rotation of the joint's rotation channels, applied in
 * their order about fixed axes (angles times angle_scale radians); its
 * local rotation L = C M C^T; its world rotation W = W[parent] L (L for a
 * root).  A root is at segment + t, t its translation channels in world
 * axes; any other joint ends at the end of its parent plus
 * W (segment + direction * l + C t), l its stretch and t its translations,
 * W its own world rotation (ASF: a bone turns its own segment) or, where
 * parent_frame[j] is set, its parent's (BVH: a joint's offset turns with its
 * parent).  parent_frame may be NULL (no joint set).
 *
 * Writes, for frames begin .. end-1, positions (frames x joints x 3) and,
 * where not NULL, world and local (frames x joints x 9).  world_rows, where
 * not NULL, keeps world to some joints (a caller that reads a few of them
 * writes a fraction of the memory): joint j's world rotation goes to row
 * world_rows[j] (-1: none) of world, then frames x world_count x 9.  NaN in a
 * channel gives NaN in that joint and its descendants.
 */
int mt_forward_kinematics(const double *values, size_t frames, size_t channels, size_t joints,
                          const long long *parent, const long long *order, const double *axis,
                          const double *direction, const double *segment, const size_t *dof_start,
                          const int *dof_kind, const size_t *dof_column,
                          const unsigned char *parent_frame, double angle_scale, size_t begin,
                          size_t end, double *positions, double *world, double *local,
                          const long long *world_rows, size_t world_count);

/*
 * Local rotations of chosen joints of a tree (the tables of mt_forward_kinematics) as unit
 * quaternions (x, y, z, w) in single precision, the keys animation formats store: for each of
 * `count` joints chosen[i], L = C M C^T per frame as mt_forward_kinematics has it, turned by
 * `turn` (3x3 row-major, applied on the left) for chosen[0] where turn is not NULL, written to
 * out[4 (i frames + f) ..] for frames f = 0 .. frames-1 (each joint's keys together); the first
 * with w >= 0, each next one on the hemisphere of the one before, so that interpolation between
 * frames takes the short way.  NaN in a channel gives NaN in its joint's keys.
 */
int mt_local_quaternions(const double *values, size_t frames, size_t channels, size_t joints, const double *axis,
                         const size_t *dof_start, const int *dof_kind, const size_t *dof_column, double angle_scale,
                         size_t count, const long long *chosen, const double *turn, float *out);

/*
 * Rotations (rotation.c), n at a time.  Matrices are 3x3 row-major (n x 9);
 * quaternions (n x 4) are (w, x, y, z), need not be unit (they are
 * normalised; a zero quaternion gives NaN) and come out with w >= 0 where
 * they are results of a conversion; rotation vectors (n x 3) are the axis
 * times the angle in radians.  Axes are MT_DOF_RX .. MT_DOF_RZ.
 *
 * Euler angles about axes[0], axes[1], axes[2] (angles times scale
 * radians) are extrinsic, about fixed axes, R = R2(c) R1(b) R0(a), or
 * intrinsic, about the axes as they turn, R = R0(a) R1(b) R2(c).
 */

/*
 * Matrices of n sequences of `count` rotations (angles n x count) about
 * axes[0 .. count-1], any sequence of axes, extrinsic or intrinsic.
 */
int mt_euler_to_matrices(const double *angles, size_t n, const int *axes, size_t count, int intrinsic,
                         double scale, double *out);

/* Unit quaternions (n x 4: w, x, y, z; w >= 0) of n Euler triples (angles n x 3) about
   Tait-Bryan or proper Euler axes (as mt_matrices_to_euler's), without the matrices. */
int mt_euler_to_quaternions(const double *angles, size_t n, const int *axes, int intrinsic, double scale,
                            double *out);

/*
 * Euler angles (n x 3, in units of 1/scale radians) of n matrices, for
 * Tait-Bryan axes (three distinct) or proper Euler axes (the first and last
 * the same): a and c in [-pi, pi], b in [-pi/2, pi/2] (Tait-Bryan) or
 * [0, pi] (proper), the ranges of scipy.  At gimbal lock (b = +-pi/2,
 * or 0 or pi) only a +- c is defined: c is then 0.
 */
int mt_matrices_to_euler(const double *matrices, size_t n, const int *axes, int intrinsic, double scale,
                         double *angles);

int mt_matrices_to_quaternions(const double *matrices, size_t n, double *quaternions);
int mt_quaternions_to_matrices(const double *quaternions, size_t n, double *matrices);
/* The rotation vectors have angles in [0, pi]. */
int mt_quaternions_to_rotvecs(const double *quaternions, size_t n, double *rotvecs);
int mt_rotvecs_to_quaternions(const double *rotvecs, size_t n, double *quaternions);

/*
 * Angle channels made continuous, in place: the `columns` (ncolumns, each < stride) of the
 * (frames, stride) array `values`.  A step of more than half a `period` between a column's
 * finite samples counts whole turns (step / period rounded, ties to even), and a sample whose
 * column has counted turns gets turns * period added: exact multiples, so that any cut of the
 * frames into calls gives the same values.  NaN and infinities stay as they are and are
 * stepped over.  last[k] and turns[k] carry column k's last finite sample and its turns from
 * call to call: NaN and 0 at a take's start.  MT_ENOMEM where ncolumns + 1 words of scratch
 * (where the columns run on) cannot be allocated; so for mt_wrap_angles.
 */
int mt_unwrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                     double period, double *last, double *turns);

/*
 * Angle channels put back into the range their take used, in place (the inverse of
 * mt_unwrap_angles once a take is smoothed).  low[k] and high[k] are the take's least and
 * greatest finite sample of column k (mt_finite_ranges): where they lie within [-P/2, P/2]
 * (P the period) that is the column's range, else where they lie within [0, P] that one,
 * else the column is left as it is.  Each finite sample of the `columns` of (frames, stride)
 * `values` outside its column's range [a, a + P] becomes v - P floor((v - a) / P).
 */
int mt_wrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                   const double *low, const double *high, double period);

/*
 * What the frames of a take say about each of its channels, widened call by call (a take
 * given in pieces): low[c] and high[c] become the least and greatest finite sample of column
 * c (start them at +inf and -inf), first[c] its first finite sample where it is still NaN
 * (start it at NaN).  values is (frames, channels).
 */
int mt_finite_ranges(const double *values, size_t frames, size_t channels, double *low, double *high,
                     double *first);

/*
 * Continuity along the middle axis of (outer, n, inner) arrays of quaternions
 * (inner quaternions per frame) or Euler triples (inner triples per frame).
 * Frame 0 is copied; each later frame becomes, of the rotations equal to it,
 * the one nearest to the output frame before it:
 *   quaternions  q or -q, whichever has a non-negative dot product;
 *   Euler        (a, b, c) or the other solution (a + h, h - b, c + h)
 *                (Tait-Bryan; (a + h, -b, c + h) when `proper`), each angle
 *                shifted by whole turns 2h; h is a half turn (pi or 180).
 * An item after one holding NaN is kept as it is: the filter restarts there.
 */
int mt_unroll_quaternions(const double *in, size_t outer, size_t n, size_t inner, double *out);
int mt_unroll_euler(const double *in, size_t outer, size_t n, size_t inner, int proper, double half_turn,
                    double *out);

/*
 * Interpolation from key 0 to key 1 by the fractions t (n of each): SLERP
 * along the shorter arc (unit quaternions out), or rotation vectors
 * v0 + t (v1 - v0), where `aligned` first replaces v0 by the rotation vector
 * of -q0 (v0 (1 - 2 pi / |v0|)) when q0 . q1 < 0, q0 and q1 the keys'
 * quaternions.
 */
int mt_slerp(const double *q0, const double *q1, const double *t, size_t n, double *out);
int mt_interpolate_rotvecs(const double *v0, const double *v1, const double *t, size_t n, int aligned,
                           double *out);

/*
 * The vectorised elementary functions of the rotation kernels, n values at a
 * time: atan2(y, x) in radians, in [-pi, pi], within 2 ulp of pi of the C
 * library's (the same at zeros of either sign and infinities, NaN for NaN);
 * sin and cos of x within about 1e-16 for |x| < 2^30, the C library's beyond.
 */
int mt_atan2(const double *y, const double *x, size_t n, double *out);
int mt_sincos(const double *x, size_t n, double *sin_out, double *cos_out);

/* How mt_interpolate_euler goes from key 0 to key 1. */
enum mt_blend {
    MT_BLEND_SLERP = 0,          /* mt_slerp of the keys' quaternions */
    MT_BLEND_EXPMAP = 1,         /* mt_interpolate_rotvecs of the keys' rotation vectors */
    MT_BLEND_ALIGNED_EXPMAP = 2  /* the same, aligned */
};

/* Which of the Euler triples of a rotation mt_interpolate_euler writes. */
enum mt_continuity {
    MT_CONTINUITY_NONE = 0,     /* mt_matrices_to_euler's, in scipy's ranges */
    MT_CONTINUITY_PATH = 1,     /* reference: a start triple per joint; each frame's triple is, as in
                                   mt_unroll_euler, the nearest the joint's triple of the frame before */
    MT_CONTINUITY_REFERENCE = 2 /* reference: a triple per frame and joint; each angle plus the whole
                                   turns that bring it nearest the reference's (ties to even) */
};

/*
 * Euler triples between keys, frames x joints of them (out: frames x joints
 * x 3), in one pass: the key triples k0 and k1 (frames x joints x 3 when
 * per_frame, else joints x 3, the same for every frame) to quaternions, the
 * `blend` (a mt_blend) at the frame's fraction t[f] (frames values), back to
 * Euler angles and the `continuity` (a mt_continuity) chosen.  Angles are in
 * degrees when `degrees`, else radians, about axes[0..2] (Tait-Bryan or
 * proper, extrinsic or intrinsic, as mt_matrices_to_euler).  The result is
 * what those kernels give in turn (mt_euler_to_matrices,
 * mt_matrices_to_quaternions, mt_slerp or mt_quaternions_to_rotvecs,
 * mt_interpolate_rotvecs and mt_rotvecs_to_quaternions, mt_quaternions_to_matrices,
 * mt_matrices_to_euler, then mt_unroll_euler from the start triples or the
 * nearest turns), to rounding; except that a key a half turn from the
 * identity has two rotation vectors, and which one rounding picks may differ.
 * `reference` may be NULL for MT_CONTINUITY_NONE.
 */
int mt_interpolate_euler(const double *k0, const double *k1, int per_frame, const double *t, size_t frames,
                         size_t joints, const int *axes, int intrinsic, int degrees, int blend, int continuity,
                         const double *reference, double *out);

/*
 * The per-frame loop of the motion combiner: output frame f of `channels`
 * values from rows of an old and a new motion (both frames x channels).
 *
 *   new' = new[new_row[f]]                                 when ramp[f] == 0
 *        = (1 - ramp[f]) new[new_row[f]] + ramp[f] new[next_row[f]]   otherwise
 *   out  = old[old_row[f]]                   where u = weight[f] == 0 or the
 *                                            channel is not selected
 *        = new'                              where u == 1
 *        = (1 - u) old[old_row[f]] + u new'  otherwise
 *
 * then, when offset_row[f] >= 0, offsets[offset_row[f]][j] is added to
 * channel offset_channel[j], j < noffsets.  next_row and ramp may be NULL
 * (no ramps: next_row = new_row, ramp = 0).  A row index of -1 means the
 * motion has no frame there: then the weight must say not to use it (and
 * unselected channels need an old row).  Pure frames are copied, never
 * multiplied, so that they equal their source bit for bit.  Writes frames
 * begin .. end-1.
 */
int mt_combine(const double *old_values, size_t old_frames, const double *new_values,
               size_t new_frames, size_t channels, size_t out_frames, const long long *old_row,
               const long long *new_row, const long long *next_row, const double *ramp,
               const double *weight, const unsigned char *selected, const long long *offset_row,
               const double *offsets, size_t offset_rows, const size_t *offset_channel,
               size_t noffsets, size_t begin, size_t end, double *out);
/*
 * Signal kernels (bands.c, iir.c, resample.c, gaps.c), float64.  Unless said
 * otherwise an array is n rows (frames) of `channels` values, consecutive
 * rows `stride` values apart (stride >= channels): a call may process a slab
 * of the columns of a wider (n, stride) array, so that threads can share the
 * channels of one array.  Outputs have the input's layout and never alias it.
 */

/*
 * The band equaliser of Bruderlin and Williams (1995).  Level G_0 is the
 * input; G_{k+1} is G_k correlated with (1 4 6 4 1) / 16, its taps 2^k frames
 * apart (no decimation: every level has all n frames), the level extended
 * past its ends by `mode` (fill value cval); band k is G_k - G_{k+1}.  Writes
 *
 *     out = in + sum_{k < levels} (gains[k] - 1) (G_k - G_{k+1}),
 *
 * which is G_levels + sum gains[k] band_k, summed so that gains of 1 give the
 * input exactly.  Requires 2^levels <= n (for n >= 1).
 */
int mt_equalize(const double *in, double *out, size_t n, size_t channels, size_t stride, size_t levels,
                const double *gains, int mode, double cval);

/*
 * How mt_sosfiltfilt extends a line a b c d by padlen samples (scipy's padtype):
 *
 *   odd       2a-d 2a-c 2a-b | a b c d | 2d-c 2d-b 2d-a
 *   even         d    c    b | a b c d | c b a
 *   constant     a    a    a | a b c d | d d d
 *   none         (no extension)
 */
enum mt_pad {
    MT_PAD_NONE = 0,
    MT_PAD_ODD = 1,
    MT_PAD_EVEN = 2,
    MT_PAD_CONSTANT = 3
};

/*
 * Forward-backward filtering by `sections` second-order sections (sos,
 * sections x 6: b0 b1 b2 a0 a1 a2, a0 = 1), as scipy.signal.sosfiltfilt: the
 * line extended by padlen samples (padtype), filtered forward from the state
 * zi[s] * (first sample), then backward from zi[s] * (last forward output),
 * the extension cut off.  zi (sections x 2) is the steady state of a unit
 * step (scipy.signal.sosfilt_zi).  Requires padlen < n (padlen is ignored
 * for MT_PAD_NONE, then n >= 1).
 *
 * Computed as scipy computes it, bit for bit, with the input read once and
 * the forward outputs written to out and read back (see iir.c).
 */
int mt_sosfiltfilt(const double *sos, size_t sections, const double *zi, const double *in, double *out, size_t n,
                   size_t channels, size_t stride, size_t padlen, int padtype);

/*
 * Upsample by up, filter by the FIR h (taps), downsample by down, as
 * scipy.signal.upfirdn, on (n, channels) rows (stride = channels): output row
 * j (begin <= j < end, at out + j * channels) is
 *
 *     sum over i of v[i] h[(skip + j) down - i up],  0 <= (skip + j) down - i up < taps,
 *
 * v[i] = in row i for 0 <= i < n, before row nbefore + i for -nbefore <= i < 0,
 * after row i - n for n <= i < n + nafter (both (rows, channels)), 0 elsewhere.
 */
int mt_upfirdn(const double *h, size_t taps, size_t up, size_t down, const double *in, size_t n, size_t channels,
               const double *before, size_t nbefore, const double *after, size_t nafter, size_t skip, size_t begin,
               size_t end, double *out);

enum mt_fill {
    MT_FILL_LINEAR = 0, /* the line between the samples around the gap (numpy.interp) */
    MT_FILL_CUBIC = 1   /* the not-a-knot cubic spline of scipy.interpolate.CubicSpline */
};

/*
 * Copies in to out and fills each run of NaN in a channel that is at most
 * max_gap frames long and has a sample on both sides.  MT_FILL_CUBIC takes
 * the spline through every sample of the stretch between the runs left
 * unfilled (or the ends of the line).  Other runs stay NaN.
 */
int mt_fill_gaps(const double *in, double *out, size_t n, size_t channels, size_t stride, size_t max_gap,
                 int method);

/*
 * The runs of NaN: (channel, first frame, frame after the last) triples, in
 * the order they end, the first `capacity` of them into runs (capacity x 3);
 * *count receives how many there are (runs may be NULL when capacity is 0).
 */
int mt_nan_runs(const double *in, size_t n, size_t channels, size_t stride, size_t *runs, size_t capacity,
                size_t *count);

/*
 * Footskate cleanup (footskate.c; Kovar, Schreiner & Gleicher, SCA 2002).
 *
 * A leg is the chain of four joints turning the thigh, shin, foot and toes
 * (hip, knee, ankle, toe).  Joint j's local rotation is L = C M C^T, C =
 * axis[j] (row-major) and M the rotation of its channels: angles about the
 * axes axes[j][0], [1], [2] (MT_DOF_RX .. MT_DOF_RZ, -1 past the last),
 * each applied about a fixed axis after the ones before.  The hip and knee
 * have at least one channel; a toe with none is no toe.  segment[] are rest
 * vectors, each in the frame of the joint that turns it: hip -> knee,
 * knee -> ankle, ankle -> ball, ankle -> heel, ball -> toe tip (zero: none).
 * Per frame a leg is given by its hip point (3), the world rotation of its
 * hip joint's parent (9) and its angles (4 x 3 radians, unused ones 0).
 * Points (5 x 3 per frame): knee, ankle, ball, heel, toe tip.
 */
struct mt_leg {
    double axis[4][9];
    int axes[4][3];
    double segment[5][3];
};

/*
 * The floor and the settings.  A point p is at height p.(up - slope) - level
 * above the floor (up unit, slope perpendicular to it).  blend: frames over
 * which adjustments fade in and out around constraints; root_window: the
 * half-width of the moving mean applied twice to the root's moves, and
 * root_passes the smoothings of what is still short before the last
 * per-frame correction; knee_soft: radians short of straight at which a knee
 * stops straightening unless it is straighter in the input; knee_keep: the
 * share of its bend in the input that the root moves to let a constrained
 * knee keep.
 */
struct mt_footskate {
    double up[3];
    double slope[3];
    double level;
    size_t blend;
    size_t root_window;
    size_t root_passes;
    double knee_soft;
    double knee_keep;
};

/* Points (nlegs x frames x 5 x 3) and, where feet is not NULL, the feet's world rotations
 * (nlegs x frames x 9) of legs given per leg and frame (hips nlegs x frames x 3, parents x 9,
 * angles x 12). */
int mt_leg_points(const struct mt_leg *legs, size_t nlegs, size_t frames, const double *hips,
                  const double *parents, const double *angles, double *points, double *feet);

/*
 * The hips (nlegs x frames x 3) and points (nlegs x frames x 5 x 3, as mt_leg_points gives them)
 * of legs placed by forward kinematics (mt_forward_kinematics): positions (frames x joints x 3)
 * of every joint, world (frames x world_count x 9) the world rotations kept.  at (nlegs x 6): the
 * joints whose positions are each leg's hip, knee, ankle, ball and toe tip (-1: no tip, which is
 * then the ball), and the row of world that turns the foot; heels (nlegs x 3): the heel from the
 * ankle in the foot's frame.  A joint or row out of range is MT_EINVAL.
 */
int mt_placed_legs(const double *positions, size_t frames, size_t joints, const double *world, size_t world_count,
                   size_t nlegs, const long long *at, const double *heels, double *hips, double *points);

/*
 * Phases 1 and 2 for one leg, of its angles and points (frames x 5 x 3, as
 * mt_leg_points gives them).  planted (frames x 2): heel and ball planted;
 * targets (frames x 2 x 3): where, read where planted; clearance (3): the
 * heights at which heel, ball and toe tip rest.
 * 1. Frame by frame a planted point keeps the target it had at the frame
 *    before; a new plant's target is put on the floor at its clearance, and
 *    set at the foot's heel-to-ball length from the other point's target
 *    when that one is planted, or was within max(1, blend / 4) frames before
 *    (a roll), in the direction between them.  -> enforced (frames x 2 x 3,
 *    NaN where not planted).
 * 2. Where both points are planted (or a roll begins) the foot turns by the
 *    smallest rotation taking heel -> ball onto the targets'; between, turns
 *    blend as rotation vectors, weights smoothstep(1 - d / w) of the nearest
 *    such frames before and after (w = min(blend, their distance)); where one
 *    point is planted the foot turns further about it if the other is below
 *    the floor, and the ankle follows it; unconstrained frames blend the
 *    ankle's shift and the foot's turn from the nearest constrained frames
 *    alike.  -> goal (frames x 3) for the ankle, turn (frames x 3, rotation
 *    vector; the foot's goal is turn times its rotation now), weight (1
 *    constrained, the larger blend weight elsewhere), reach (the longest
 *    hip-to-ankle distance with the knee bent at least min(knee_soft, its
 *    bend) and knee_keep times its bend), knee (4: the hinge axis in the
 *    hip joint's frame, its channel's or the take's mean bend axis, and the
 *    side it bends to, +1 or -1).
 */
int mt_footskate_plan(const struct mt_leg *leg, size_t frames, const double *angles, const double *points,
                      const unsigned char *planted, const double *targets, const double *clearance,
                      const struct mt_footskate *opt, double *enforced, double *goal, double *turn,
                      double *weight, double *reach, double *knee);

/*
 * Phase 3 for one or two legs (hips, goals legs x frames x 3; reaches,
 * weights legs x frames): the root's translation (frames x 3) that puts each
 * hip within reach of its goal where its weight is positive.  Per frame the
 * least move: onto one sphere, or for two the projection onto one that lies
 * in the other ball, else onto their intersection circle; the moves are
 * smoothed (root_window), what is still short smoothed in root_passes times,
 * and the rest moved per frame.
 */
int mt_footskate_root(size_t legs, size_t frames, const double *hips, const double *goals,
                      const double *reaches, const double *weights, const struct mt_footskate *opt,
                      double *root);

/*
 * Phases 4 and 5 for one leg (its points as for mt_footskate_plan): the new
 * angles (frames x 4 x 3).  Frames that
 * are constrained, blended, or whose root moved, are solved by two-bone IK:
 * the knee bends about its hinge to the goal's distance (within reach, never
 * past straight), the hip turns the leg onto the goal, the ankle takes the
 * foot's goal (a joint with fewer than three channels turns its segment
 * exactly where asked; a planted foot's ankle is re-aimed twice so that the
 * planted point lands).  A free foot below the floor is lifted by the upper
 * envelope of its depths under a bump blend / 2 frames wide, and per frame
 * by what remains; toe tips below the floor bend the toes up.  Other frames
 * keep their angles bit for bit.
 */
int mt_footskate_solve(const struct mt_leg *leg, size_t frames, const double *hips, const double *parents,
                       const double *angles, const double *points, const unsigned char *planted,
                       const double *goal, const double *turn, const double *weight, const double *knee,
                       const double *root, const double *clearance, const struct mt_footskate *opt,
                       double *out);

/*
 * Footplant detection (motiontheater.contacts) over rows of n frames: the
 * thresholds, already in the samples' units and scaled.
 */
struct mt_plant_thresholds {
    double sure_height, sure_speed;   /* sure: height < sure_height and central < sure_speed */
    double height, speed;             /* close: height < height and speed < speed, or sure */
    double firm_height, firm_speed;   /* firm: likewise, or sure (firm frames are close) */
    double merge_speed;               /* plants gap frames apart merge when every frame between is slower */
    double rise;                      /* a plant's ends more than this above its lowest frame are cut */
    size_t gap, shortest;             /* frames */
};

/*
 * The footplants of rows of samples (heights, speed, central: rows x n;
 * mask: rows x n, 1 planted, 0 not).  A plant is a run of close frames
 * holding a firm one; plants whose gap is at most th->gap frames merge when
 * every frame of the gap has speed < merge_speed; each plant's first and
 * last frames are cut back to those at most rise above its lowest height
 * (the minimum over the plant, gaps included; NaN if any is NaN) or sure;
 * plants shorter than th->shortest frames then are dropped unless they hold
 * a sure frame.  NaN compares false.
 */
int mt_plant_masks(const double *heights, const double *speed, const double *central, size_t rows, size_t n,
                   const struct mt_plant_thresholds *th, unsigned char *mask);

/*
 * Speeds of points over frames, in their unit per second (rate: frames per
 * second).  points: tracks x frames x per_frame x 3, of which the points
 * which[0 .. count-1] (< per_frame) of each frame are measured; speed
 * (tracks x count x frames): the larger of the distances to the frames
 * before and after, times rate (so that neither difference quotient finds
 * the point faster); central (the same, or NULL): the length of the central
 * difference (p[t+1] - p[t-1]) / 2, one-sided at the ends, times rate.  A
 * single frame has speed 0; NaN in, NaN out.
 */
int mt_point_speeds(const double *points, size_t tracks, size_t frames, size_t per_frame, const size_t *which,
                    size_t count, double rate, double *speed, double *central);

/*
 * The cleanup written back to the channels of a motion (values, out: frames
 * x channels; out may not alias values): out is values but where a leg's
 * solved angle differs from its input angle (angles, solved: legs x frames x
 * 12, as mt_footskate_solve takes and gives them), written to its column as
 * solved / angle_scale (columns: legs x 12, the column of each slot or -1
 * for none), and in the root's translation columns (root_columns, 3), to
 * which root (frames x 3) is added where it is not 0 (so that a -0.0 stays).
 * Every other value is copied bit for bit.  The columns given must be
 * distinct and below channels, else MT_EINVAL.
 */
int mt_footskate_write(size_t legs, size_t frames, size_t channels, const double *values, const double *angles,
                       const double *solved, const long long *columns, double angle_scale, const double *root,
                       const long long *root_columns, double *out);
/*
 * Retargeting (retarget.c): a motion of a source skeleton as the rotation
 * channels of a target skeleton.
 *
 * A tree is the tables of mt_forward_kinematics (see there) with its joint
 * and channel counts; parent_frame may be NULL.
 */
struct mt_tree {
    size_t joints, channels;
    const long long *parent, *order;
    const double *axis, *direction, *segment;
    const size_t *dof_start, *dof_column;
    const int *dof_kind;
    const unsigned char *parent_frame;
    double angle_scale;
};

/*
 * The plan of a retarget, per target joint j (rows of the arrays):
 *   follow[j]        the source joint whose world rotation it follows, or -1:
 *                    it keeps its rest rotation (its channels 0);
 *   correction[9j..] P: its wanted world rotation is D = A W_s P, W_s the
 *                    source joint's world rotation, A = align (row-major,
 *                    source world axes to target world axes);
 *   key_points[2j..] source points a, b (rows of the source's FK positions)
 *                    whose direction p_b - p_a is the one the joint's bone
 *                    should point in, or -1 -1: none;
 *   key_vector[3j..] that bone at rest, target world axes;
 *   refit[j]         when set, D is turned each frame by the smallest
 *                    rotation that takes D key_vector onto A (p_b - p_a),
 *                    so that the bone points where the source's points lie
 *                    even when source joints between them turn;
 *   hinge[j]         a target joint with one rotation channel that hangs
 *                    from j (unmapped joints between), or -1: a joint with
 *                    three rotation channels then turns D about its own bone
 *                    by the smallest angle that lets the hinge aim its bone
 *                    at its source direction (fading out as their bend
 *                    nears none, where any such turn serves);
 *   aim[3j..]        the rest direction (target world axes) that a joint with
 *                    one or two rotation channels turns as near as it can to
 *                    where D turns it, or 0 0 0 (then: one channel takes D's
 *                    twist about its axis, two the Euler angles with the
 *                    missing axis between, dropped).
 * Its local rotation L = W_parent^T D, M = C^T L C (C its axis), becomes its
 * rotation channels (Euler angles of M about their axes, in the order the
 * tree applies them, about fixed axes: a, c in [-pi, pi], b in [-pi/2, pi/2]),
 * in units of 1/angle_scale radians; its world rotation is then W_parent
 * C M' C^T, M' the rotation its channels make.
 */
struct mt_retarget_plan {
    const long long *follow;
    const double *correction;
    const long long *key_points;
    const double *key_vector;
    const unsigned char *refit;
    const long long *hinge;
    const double *aim;
    double align[9];
};

/*
 * Writes, for frames begin .. end-1 of values (frames x source->channels),
 * the rotation channels of every target joint into out (frames x
 * target->channels); its other channels are not touched.  MT_EINVAL for
 * tables out of range or a target joint with more than three rotation
 * channels, or with two about one axis.
 */
int mt_retarget(const double *values, size_t frames, const struct mt_tree *source, const struct mt_tree *target,
                const struct mt_retarget_plan *plan, size_t begin, size_t end, double *out);
/*
 * Search by example (dtw.c, knn.c, features.c).
 *
 * Sequences and point sets are (rows, dims) row-major float64.  Every value
 * searched must be finite: a NaN or an infinity in a sequence, a point or a
 * query is MT_EINVAL (a NaN orders nothing).  Distances are squared Euclidean,
 * sum_k (a_k - b_k)^2 over the dims, and no square root is taken anywhere: a
 * bound and a distance then compare exactly (see dtw.c and knn.c for why the
 * pruning loses nothing after rounding either).
 *
 * Dynamic time warping of a (m x dims) and b (n x dims): the least sum of
 * cost(i, j) = |a_i - b_j|^2 over a warping path from (0, 0) to (m-1, n-1) of
 * steps (1, 0), (0, 1), (1, 1) within the Sakoe-Chiba band |i - j| <= radius
 * (a radius >= max(m, n) is no band; 0 with m = n is the squared Euclidean
 * distance).  No path: +inf (|m - n| > radius, or one of them empty; two empty
 * sequences are at 0).
 */

/*
 * The LB_Keogh envelope of x (n x dims) for a band of `radius`: upper and
 * lower (n x dims) are the maximum and minimum of x over frames t - radius ..
 * t + radius (within 0 .. n-1), dimension by dimension.  O(n dims) for any
 * radius; scratch for min(n, 2 radius + 2) frame indices.
 */
int mt_lb_envelope(const double *x, size_t n, size_t dims, size_t radius, double *upper, double *lower);

/*
 * LB_Keogh of a candidate (n x dims) against a query's envelope (upper, lower
 * as mt_lb_envelope gives them for the query's n frames): the sum over frames
 * and dims of the squared distance from the candidate's sample to the interval
 * [lower, upper] there; at most the DTW distance of query and candidate of the
 * same length within the same radius.  The sum stops as soon as it exceeds
 * threshold (+inf: never), and *bound is then that partial sum, above the
 * threshold and still a lower bound.  A NaN threshold is MT_EINVAL.
 */
int mt_lb_keogh(const double *candidate, const double *upper, const double *lower, size_t n, size_t dims,
                double threshold, double *bound);

/*
 * The DTW distance of a (m x dims) and b (n x dims) within `radius`, into
 * *distance; +inf where every cell of some row i (frame i of a) exceeds
 * threshold (the distance then does, too), +inf for no threshold.  O(m (2
 * radius + 1) dims); scratch for 2 n doubles.  A NaN threshold is MT_EINVAL.
 */
int mt_dtw(const double *a, size_t m, const double *b, size_t n, size_t dims, size_t radius, double threshold,
           double *distance);

/* What mt_dtw_search did with its candidates: each is counted once. */
struct mt_dtw_stats {
    size_t warped;    /* DTW computed to the end (the first k candidates among them) */
    size_t abandoned; /* DTW stopped at a row above the k-th best distance found so far */
    size_t pruned;    /* never warped: the lower bound was above the k-th best distance */
};

/*
 * The k windows of series (n x dims, of element type dtype: float32 halves
 * what a database holds, and is read as the doubles its values are) nearest
 * to query (m x dims) by DTW within radius: the candidates are the windows
 * of m frames at starts[0 .. count-1] (strictly increasing, each at most
 * n - m).  hits and distances (k each)
 * receive their starts and distances, nearest first, a tie to the lower start;
 * *found = min(k, count) of them.  This is exactly what computing mt_dtw for
 * every candidate and sorting (distance, start) gives: the search only skips
 * windows that could not be among those k.
 *
 * It warps k seeds (the candidates of least LB_Keogh among about max(1024,
 * 4k) spread evenly over them), computes LB_Keogh of every candidate against
 * the query's envelope (bounds, count doubles: each candidate's bound, or
 * where it passed the k-th distance of the seeds, the partial sum that did;
 * never above the candidate's distance), then warps the others in the order of
 * their bounds (then starts), each abandoned above the k-th best found so far,
 * until the next bound is above it.  order (count) is the caller's scratch for
 * that order.  stats may be NULL.  k >= 1; count 0 finds nothing.  Scratch: 2
 * m dims + 2 m doubles and min(k, count) indices.
 */
int mt_dtw_search(const double *query, size_t m, int dtype, const void *series, size_t n, size_t dims,
                  size_t radius, const size_t *starts, size_t count, size_t k, double *bounds, size_t *order,
                  size_t *hits, double *distances, size_t *found, struct mt_dtw_stats *stats);

/*
 * A k-d tree over the rows of points (n x dims, dims >= 1, of element type
 * dtype: float32 halves its memory, its values read as the doubles they are),
 * in buffers the caller allocates and owns.  leaf_size >= 1 rows at most in
 * a leaf; depth from mt_kdtree_depth; index (n): the rows, each node's a
 * contiguous range; rows (n x dims, of dtype): row index[i] of points at row
 * i, so that a leaf is read from contiguous memory; split_dim and split_value
 * (2^depth - 1 each, none for depth 0): the internal nodes in heap order
 * (node i's children are 2i+1 and 2i+2).  points is read by mt_kdtree_build
 * only (queries read rows), and may be NULL for them.
 */
struct mt_kdtree {
    int dtype;
    const void *points;
    size_t n, dims, leaf_size, depth;
    size_t *index;
    void *rows;
    size_t *split_dim;
    double *split_value;
};

/* The depth of the tree of n rows in leaves of at most leaf_size (>= 1): the least d with ceil(n / 2^d) <= leaf_size. */
int mt_kdtree_depth(size_t n, size_t leaf_size, size_t *depth);

/*
 * Fills the tree's index, rows, split_dim and split_value from its points, n,
 * dims, leaf_size and depth (which must be mt_kdtree_depth's).  O(n log n);
 * scratch for 2 dims doubles.
 */
int mt_kdtree_build(struct mt_kdtree *tree);

/*
 * The k nearest rows to each of queries (count x tree->dims), exactly: row i
 * of indices and distances (count x k each) receives the rows nearest query i
 * and their squared distances, sorted by distance then row, found[i] (count)
 * of them (min(k, the rows not excluded)); the slots past found[i] get
 * SIZE_MAX and +inf.  exclude (count x 2) or NULL: query i ignores the rows
 * exclude[2i] .. exclude[2i+1]-1 (a frame and its neighbours).  Exactly what
 * sorting every row's distance gives, ties included.  MT_EINVAL also where
 * the tree's buffers hold a dimension or row out of range.  Scratch: dims doubles.
 */
int mt_kdtree_query(const struct mt_kdtree *tree, const double *queries, size_t count, size_t k,
                    const size_t *exclude, size_t *indices, double *distances, size_t *found);

/*
 * Relational features (Müller, Röder and Clausen 2005), frames x features.
 *
 * Hysteresis: feature f turns on in a frame whose value is above high[f] and
 * off in one below low[f] (low[f] <= high[f], else MT_EINVAL); in between, and
 * for NaN, it keeps the state of the frame before, initial[f] before the first
 * (initial NULL: off).  on (n x features) receives 1 or 0.
 */
int mt_hysteresis(const double *values, size_t n, size_t features, const double *low, const double *high,
                  const unsigned char *initial, unsigned char *on);

/* Bit f of words[t] (n) is whether bits[t * features + f] is non-zero; features <= 64. */
int mt_pack_bits(const unsigned char *bits, size_t n, size_t features, uint64_t *words);

/*
 * The relations of a body, frame by frame, in one pass: points (n x npoints x
 * 3, row-major: frame, point, axis) and scalars (n x nscalars) of the body at
 * `rate` frames a second (finite, > 0); relation r (count <= 64) reads them as
 * its kind says, its value multiplied by sign (after |.| where absolute), and
 * turns on above `on`, off below `off` (off <= on), else (NaN too) keeps its
 * state of the frame before (off before the first), as mt_hysteresis; bit r
 * of words[t] (n) is its state in frame t.  values (n x count) receives the
 * values, or is NULL.  An index out of range, an axis not 0..2, an unknown
 * kind or a NaN threshold is MT_EINVAL.
 */
enum mt_relation_kind {
    MT_RELATION_DIFFERENCE = 0, /* p[a][axis] minus the lower of p[b][axis] and p[c][axis]
                                   (c < 0: p[b][axis]; b < 0, with c < 0: 0) */
    MT_RELATION_BEND = 1,       /* 180 minus the angle at p[b] between p[a] and p[c], degrees */
    MT_RELATION_SPEED = 2,      /* |dp[a]/dt| (central differences, one-sided at the ends; 0 in a
                                   body of one frame) */
    MT_RELATION_LEAN = 3,       /* the angle of p[a] from the y axis, degrees */
    MT_RELATION_SCALAR = 4      /* scalars[a] */
};
struct mt_relation {
    int kind;
    int a, b, c;
    int axis;
    int absolute;
    double sign, off, on;
};

int mt_relations(const double *points, size_t n, size_t npoints, const double *scalars, size_t nscalars, double rate,
                 const struct mt_relation *relations, size_t count, double *values, uint64_t *words);

/*
 * The runs of equal words (n) as segments: the first `capacity` of them into
 * first (their first frames) and values (their words); *count receives how
 * many there are (at most n; first and values may be NULL for capacity 0).
 */
int mt_segments(const uint64_t *words, size_t n, size_t *first, uint64_t *values, size_t capacity, size_t *count);

/*
 * An inverted index over the segments of many takes, in buffers the caller
 * allocates.  words (segments): the word of each segment, the takes' one
 * after another; take_first (takes + 1): take t holds segments take_first[t]
 * .. take_first[t+1]-1 (0 first, segments last, non-decreasing).  Built by
 * mt_feature_index_build (CSR): keys (capacity segments) the distinct words
 * ascending, nkeys of them; offsets (capacity segments + 1): the segments of
 * keys[i] are ids[offsets[i] .. offsets[i+1]-1] (ids: segments), ascending.
 */
struct mt_feature_index {
    const uint64_t *words;
    const size_t *take_first;
    size_t segments, takes;
    uint64_t *keys;
    size_t *offsets;
    size_t *ids;
    size_t nkeys;
};

/* Fills keys, offsets, ids and nkeys from words and take_first; in place, O(segments log segments). */
int mt_feature_index_build(struct mt_feature_index *index);

/*
 * Where the query (length >= 1 words) occurs: the segments s, ascending, with
 * words[s + j] == query[j] for j < length and all of s .. s + length - 1 in one
 * take (an exact match of consecutive segments; a query made by mt_segments has
 * no two equal words in a row, nor has any take).  The first `capacity` into
 * hits; *count receives how many there are.  Reads the posting list of the
 * query's rarest word only.
 */
int mt_feature_index_find(const struct mt_feature_index *index, const uint64_t *query, size_t length, size_t *hits,
                          size_t capacity, size_t *count);
/*
 * The take check (check.c): what is wrong with the channels of a take, in one pass.
 *
 * values is (rows, stride), channel k of row t at values[t * stride + k].  Rows begin .. end-1
 * are checked; the rows around them are read as neighbours only (so that a take checked in
 * pieces, each with 3 rows of its neighbours before and 2 after, finds what the whole take
 * gives).  Each event is a row of 5 in events (capacity x 5): channel, first row, last row
 * (inclusive), kind (an mt_check_kind) and the row where its size peaks; its size goes to
 * sizes[i].  *count receives how many events there are, in the order they end; only the first
 * `capacity` are written.  Per channel, roughness[k] receives the sum of r^2 over the rows
 * checked, r = x[t] - (x[t-1] + x[t+1]) / 2, taken where both neighbours exist and |r| is
 * within spike_limit[k], and smooth_rows[k] how many such rows there were.
 */
enum mt_check_kind {
    MT_CHECK_GAP = 0,    /* a run of NaN; size 0 */
    MT_CHECK_FROZEN = 1, /* a run of rows equal to the first of them, at least min_run long, or
                            shorter where it touches row begin - 1 or end - 1 (a piece of a run
                            that the pieces around may continue); size: the value held */
    MT_CHECK_SPIKE = 2,  /* rows farther than spike_limit[k] from the median of the five around
                            them (the line mirrored at its ends: d c b | a b c d | c b a; no
                            spike is told beside a NaN nor in lines of fewer than 3 rows); size:
                            x minus that median, the largest */
    MT_CHECK_STEP = 3,   /* rows whose change from the row before differs by more than
                            step_limit[k] from the changes into the rows before and after
                            (one of them at the ends); size: that change minus the mean of the
                            changes beside it, the largest */
    MT_CHECK_REPEAT = 4  /* a run of rows equal to the row before in every channel; channel is
                            `channels`, size 0 */
};

int mt_check_channels(const double *values, size_t rows, size_t channels, size_t stride, size_t begin, size_t end,
                      const double *spike_limit, const double *step_limit, size_t min_run, size_t *events,
                      double *sizes, size_t capacity, size_t *count, double *roughness, size_t *smooth_rows);

/*
 * The pace of a take's steps (check.c), for the rows missing between two (dropped frames).
 * Step t goes from row t to row t + 1; for 1 <= t <= rows - 3, with d_k = x[t+1] - x[t] the
 * change of channel k over the step and m_k the mean of the changes into row t and out of row
 * t + 1, summed over the channels whose four values there are finite:
 * moved[t] = sum_k weight[k] m_k^2, paced[t] = sum_k weight[k] d_k m_k and stepped[t] =
 * sum_k weight[k] d_k^2.  paced / moved is how many steps of motion the step holds: 1 where the
 * take moves on evenly, 2 where a row is missing between rows t and t + 1, and stepped - 2 s
 * paced + s^2 moved how far from s steps it lies; weight[k] >= 0 (1 / the variance of d - m
 * that noise gives the channel) makes them sums in units of that noise.  Steps 0, rows - 2 and
 * rows - 1 (every step below 4 rows) get 0.  Rows as mt_check_channels reads them (stride);
 * moved, paced and stepped have rows entries.  A weight that is negative or not finite is
 * MT_EINVAL.
 */
int mt_check_pace(const double *values, size_t rows, size_t channels, size_t stride, const double *weight,
                  double *moved, double *paced, double *stepped);

/*
 * How rough each channel of a take is (check.c), for the weights of mt_check_pace: over rows
 * 1 .. rows - 2, r = (x[t-1] + x[t+1]) * -0.5 + x[t]; squares[k] += the sum of r^2 and counts[k]
 * += how many rows' r are finite (the others, beside a gap or an infinity, are left out).  Adds to
 * what squares and counts hold, so that a take's blocks (each with the row before and after it)
 * add up to the whole take's.  Rows as mt_check_channels reads them (stride).
 */
int mt_check_roughness(const double *values, size_t rows, size_t channels, size_t stride, double *squares,
                       size_t *counts);

/*
 * Where the feet rest, and the floor they rest on (ground.c).  points (nlegs x frames x 5 x 3) as
 * mt_leg_points gives them; their contact points are heel, ball and toe tip, k = 0, 1, 2 in that
 * order; tips (nlegs): 1 where a leg has a toe tip; up: a signed coordinate axis.
 *
 * mt_resting_points: resting (nlegs x frames x 3) is 1 where contact point k rests: slower than
 * rest_speed m/s (its speed the larger of its steps to the frames before and after, times
 * frame_rate, in metres by meters_per_unit; 0 in a take of one frame) with a height along up that
 * is a number.  A point that rests so in fewer than `needed` frames rests instead in the
 * `needed` slowest of the frames where it lies no higher than the 20th percentile of its heights
 * (numpy's linear percentile, NaN left out; ties in frame order, NaN speeds last), those of them
 * with a height.  A leg without a toe tip has no resting tip.
 *
 * mt_fit_floor: the floor under the resting samples: heights along up z = g . (x, y) + c_p,
 * (x, y) a sample's horizontal coordinates (the axes where up is 0, in order) less their mean over
 * the samples, c_p a rest height per contact point that has samples, fitted by least squares to
 * every s-th resting sample in the order leg, frame, point (s the least that leaves at most
 * `samples` of them), the gradient held back by a ridge of sqrt(samples taken) * prior on each of
 * its components; fitted three times, each time to the samples less than `band` above the last
 * fit.  A gradient longer than max_tilt is shortened to it.  Out: slope (3; the gradient, 0
 * along up), level (where the floor meets the line of up through the horizontal origin: the lowest
 * rest height less slope . the samples' mean), clearance (nlegs x 3): each contact point's rest
 * height above the lowest (0 for a point without samples; a leg without a toe tip gets its
 * ball's for its tip).  MT_EINVAL where up is no coordinate axis, nothing rests or the equations
 * are singular.
 */
int mt_resting_points(const double *points, size_t nlegs, size_t frames, const int *tips, const double *up,
                      double frame_rate, double meters_per_unit, double rest_speed, size_t needed,
                      unsigned char *resting);
int mt_fit_floor(const double *points, const unsigned char *resting, size_t nlegs, size_t frames, const int *tips,
                 const double *up, double band, double prior, size_t samples, double max_tilt, double *level,
                 double *slope, double *clearance);

/*
 * The take check's measures of the legs, frame by frame (check_legs.c).  points (nlegs x
 * frames x 5 x 3): knee, ankle, ball, heel and toe tip of each leg (as mt_leg_points gives
 * them); hips (nlegs x frames x 3).  Lengths in any one unit, meters_per_unit metres each; a
 * point p lies p.(up - slope) - level above the floor (up a unit vector, slope perpendicular to
 * it, as in struct mt_footskate); rest (nlegs x 3): the heights at which heel, ball and toe tip
 * rest on it; tips (nlegs): 1 where the leg has a toe tip.  Out:
 *
 *   drift (nlegs x 2 x frames), of heel and ball: where the point is on the floor, its distance
 *       across up from where it was at the first frame of that run of frames on the floor; NaN
 *       elsewhere.  On the floor: less than floor_height metres above its lowest along up over
 *       the `window` frames before and after (the take's ends cut the window; NaN heights are
 *       left out), and slower than floor_speed m/s across up (the larger of its steps to the
 *       frames before and after, times frame_rate; 0 in a take of one frame).
 *   depth (nlegs x frames): how far below where it rests the lowest of heel, ball and (with a
 *       tip) toe tip lies; NaN where none is a number.
 *   back (nlegs x frames): the degrees the knee bends backwards: the angle between thigh (hip
 *       to knee) and shin (knee to ankle) where the turn from thigh to shin goes the other way
 *       round than the turn from shin to foot (ankle to ball), the foot lies across the shin
 *       (the cosine between them under foot_across: a pointed foot along the shin tells
 *       nothing) and the bend is under `folded` degrees (a knee folded further turns its hinge
 *       with the thigh); 0 elsewhere, and where a point is NaN.
 *   standing (6): how many of the legs' frames stand along +x, -x, +y, -y, +z and -z: the axis
 *       of hip minus ankle's largest coordinate (the first of equals) and its sign; frames where
 *       hip or ankle is not a number are not counted.
 *
 * MT_ENOMEM where scratch of 4 x frames numbers cannot be had.
 */
struct mt_leg_check {
    double up[3], slope[3], level;
    double meters_per_unit, frame_rate;
    size_t window;
    double floor_height, floor_speed;
    double foot_across, folded;
};

int mt_check_legs(const double *points, const double *hips, size_t nlegs, size_t frames, const double *rest,
                  const int *tips, const struct mt_leg_check *check, double *drift, double *depth, double *back,
                  size_t *standing);

/*
 * The take check's candidate spikes of one joint's rotation trimmed (check_spikes.c).  q (frames
 * x 4) the joint's rotation at each frame, unit quaternions; runs i: frames first[i] .. last[i]
 * (first <= last < frames).  While the run holds more than one frame and its first or last frame
 * lies within limit[i] degrees of the path between the frames around the run (the SLERP between
 * them at the frame's place, r - first + 1 of last - first + 2 of the way), that frame is dropped,
 * the first before the last.  first_out, last_out: the frames left; largest: the most degrees any
 * of them lies from that path.  A run with no frame before or after it, or with a NaN among its
 * frames and those around, is left whole and its largest is NaN.
 */
int mt_check_trim(const double *q, size_t frames, size_t runs, const size_t *first, const size_t *last,
                  const double *limit, size_t *first_out, size_t *last_out, double *largest);

/*
 * What spikes of one joint's rotation move (check_spikes.c): the points the joint turns, from a
 * take's forward kinematics.  places (frames x joints x 3) are every joint's end, world (frames
 * x turned x 9, row-major) world rotations, the joint's at row `row`; the joint's channels turn
 * about its world rotation times axis (9); the points (count of them, indices of joints) are
 * what it turns, their offsets taken from joint `origin`'s place.
 */
struct mt_turned {
    const double *places, *world;
    size_t frames, joints, joint, origin, turned, row;
    const double *axis;
    const size_t *points;
    size_t count;
};

/*
 * For runs i of rows first[i] .. last[i] (1 <= first <= last <= frames - 2) of the joint, whose
 * rotation at each frame is q (frames x 4, unit quaternions): off[i], the farthest any point
 * lies, at a row of the run, from midway between where it is at the rows before and after, in
 * metres (places times meters), twice that for a run of several rows; filled[i], the farthest
 * any point lies, at a row r of the run, from where the joint's rotation on the SLERP from row
 * before[i] to row after[i] (before < after < frames; at (r - before) / (after - before) of the
 * way: the path between the rows around the run for before = first - 1 and after = last + 1,
 * the pace going on for a row r = after + 1) would put it, the joints below as they are, in
 * metres: its offset from the origin, in the joint's channels' axes, turned by A^T B less
 * itself (A, B the matrices of the actual and the SLERP's rotation).  NaN distances are left
 * out, and a run where none is a number gets 0.  MT_ENOMEM where scratch of 27 numbers a row
 * cannot be had.
 */
int mt_check_seen(const struct mt_turned *k, const double *q, size_t runs, const size_t *first, const size_t *last,
                  const size_t *before, const size_t *after, double meters, double *off, double *filled);

/*
 * The elbows of a take, frame by frame (check_arms.c): how far each bends forward (positive) or
 * backwards (negative), in degrees.  positions (frames x joints x 3) are every joint's, world
 * (frames x turned x 9) the world rotations of some joints (row-major).  Arm a's shoulder, elbow
 * and wrist are where joints place[3a], place[3a + 1] and place[3a + 2] are, and its upper arm
 * turns with world rotation turning[a] (< turned).  At each frame, with u the upper arm and f the
 * forearm, n = W^T (u x f) is their turn in the axes of that rotation.  The frames bent past the
 * angle whose tangent is tan_bent (u . f < |n| / tan_bent, |n| > 0) tell the elbow's axis: the
 * eigenvector of the largest eigenvalue of the mean of n n^T / |n|^2 over them, the way round
 * that most of them turn about it.  Where at least max(2, least) frames bend so and that
 * eigenvalue exceeds hinge (the turns share an axis), judged[a] is 1 and bend (arms x frames)
 * receives atan2(n . axis, u . f) in degrees (NaN where a position is NaN); elsewhere judged[a]
 * is 0 and the arm's bends NaN.
 */
int mt_check_elbows(const double *positions, size_t frames, size_t joints, const double *world, size_t turned,
                    const size_t *turning, const size_t *place, size_t arms, double tan_bent, double least,
                    double hinge, double *bend, unsigned char *judged);

/* MT_CDEF_END */

#endif /* MTCORE_H */
