/*
** number.h -- the one strict number parser of linewise: scene keys, the
** command line, state files, schedule tables, ladders and polygons all read
** numbers through it, so they all accept the same text.
**
** Accepted: an optional sign, decimal digits with an optional fraction and
** an optional exponent ("12", "-0.5", ".5", "3e-4", "1E+6").  Refused: hex
** ("0x10"), "inf", "nan", blanks inside, trailing characters, an empty
** token, and values that overflow a double.  Results too small for a normal
** double read as the nearest subnormal (or 0), so every %.17g a state
** file writes reads back.
*/
#ifndef LINEWISE_NUMBER_H
#define LINEWISE_NUMBER_H

#include <stddef.h>
#include <stdio.h>
#include <sys/types.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* LW_EUSAGE unless the C library's numbers use '.' as the decimal point:
** every file linewise reads or writes does, and printf and strtod follow
** LC_NUMERIC, so a program that calls setlocale(LC_ALL, "") (a GUI
** toolkit does) would refuse "0.5" and write "0,5".  Checked where a scene,
** a run or a trace is read. */
lw_status lw_number_locale_ok(lw_error *err);

/* The first len characters of s as a finite double; 1 on success. */
int lw_number_parse_n(const char *s, size_t len, double *out);

/* The whole string s as a finite double; 1 on success. */
int lw_number_parse(const char *s, double *out);

/* Writes v to f as the shorter of %.15g and %.17g that reads back as v
** (%.17g always does; 0.1 stays 0.1).  A trace's energies printed to 10
** digits lost the fluctuations of a large energy at a low temperature: the
** heat capacity of a 10-coordinate harmonic wire read 21.9 for 5. */
void lw_number_print_exact(FILE *f, double v);

/* The same into buf (n bytes, at least 32), returned. */
char *lw_number_format_exact(char *buf, size_t n, double v);

/* The whole string s as a whole number in [lo, hi] (|lo|, |hi| <= 2^53, so
** every value is exact); "1e3" counts as 1000.  1 on success. */
int lw_number_parse_whole(const char *s, double lo, double hi, long long *out);

/* Removes a UTF-8 byte-order mark from the start of the text line s, in
** place: editors on Windows begin a file with one, and every reader of a
** text input drops it from its first line, as the scene reader does (it
** showed as nothing in "got ''" messages). */
void lw_text_drop_bom(char *s);

/* The next line of a text input f into *buf (getline's buffer, *cap its
** size), without its line end (LF, CRLF or a lone trailing CR) and, on the
** first line, without a byte-order mark; *line counts the lines read.
** Returns its length, -1 at the end, -2 for a line holding a NUL byte
** (which would end it early as a string and drop the rest unseen) or a
** failed read (errno set; ENOMEM when out of memory). */
long lw_text_next_line(FILE *f, char **buf, size_t *cap, long *line);

/* getline(3) for the readers of text files, which a NUL byte ends, with it
** (each reader refuses a line that holds one), and which gives at most
** LW_TEXT_LINE_MAX bytes of a longer line (what follows comes as the next
** line, which a reader finds malformed): /dev/zero or a sparse file of
** gigabytes, named as a state, a table or points, grew one line until the
** machine's memory was gone.  -1 at the end (or a read error: ferror), -2
** out of memory (errno ENOMEM), which a reader must not take for the end
** (stats took the rows before as the whole trace). */
#define LW_TEXT_LINE_MAX (64L << 20)
ssize_t lw_text_getline(char **buf, size_t *cap, FILE *f);

/* What every text reader says of a line with a NUL byte in it (-2 above). */
#define LW_TEXT_NUL_LINE "a NUL byte inside the line (UTF-16 text, as some editors save 'Unicode', has one in " \
                         "every other byte): expected UTF-8 or ASCII text"

/* Names a character in value that prints like a blank or like nothing, or
** like a character of a number it is not (a minus sign, a full-width
** digit), or a byte that is no text, for a message that shows the value:
** " (byte K is a no-break space, U+00A0: delete it or type a plain space)",
** or "" if there is none.  buf holds it. */
const char *lw_text_unseen_char(const char *value, char *buf, size_t n);

/* LW_EINPUT with err where path names what is not a regular file: a FIFO,
** a socket or a terminal, which a reader would wait on for ever (opening a
** FIFO waits for a writer), a folder, whose reading fails with no more than
** "read error", or another device; else LW_OK (a missing file too: its
** opening says so). */
lw_status lw_text_plain_file(const char *path, lw_error *err);

/* What a number in a comma or a point locale's writing means to say, as a
** hint to add to a message (into hint, "" if none): digits grouped in
** threes by '.' or ',' ("1.000", "10.000.000", "1,000,000", "1,000.5") are
** a thousands separator where a whole number is wanted (whole), the groups
** are more than one or a fraction follows them; a comma between digits
** otherwise is a decimal comma.  A leading group of zeros ("0.000") is none.
** Returns 1 where s must be refused although it parses: "1.000" for a
** whole number, which read as one sweep, or seed 1. */
int lw_number_separator_hint(const char *s, int whole, char *hint, size_t n);

/* Splits s at blanks (commas too when `commas` is 1 or 2) into at most max
** numbers; returns how many tokens there were (more than max are counted
** but not stored), or -1 if a token is not a number.  With commas 2, -2
** where a comma stands alone between two numbers ("0,5") in a list that
** also has blanks alone between two: "0,5 0,7" is two numbers with decimal
** commas more likely than four (and so is the SVG style "10,20 30,40", which
** "10 20 30 40" says plainly); "1, 2, 3", "1,2,3" and "0 0, 0.5, 1 1" read;
** and -3 where a field is empty (lw_text_empty_field).  A run's own
** scene.ini takes 1, as older releases wrote any mix. */
int lw_number_list(const char *s, int commas, double *out, int max);

/* Whether s has an empty field between commas or before the first ("1,,2"
** read as 1 2: a spreadsheet's blank cell shifting the values after it;
** ",1"); empty fields at the end ("x,y,z,,,", a point cloud's blank
** normals) are none. */
int lw_text_empty_field(const char *s);

/* What to add to a message on a list refused with count (-2: mixed
** separators, -3: an empty field), else "". */
const char *lw_number_list_hint(int count);

#ifdef __cplusplus
}
#endif

#endif
