/* main.c -- the linewise command line (placeholder until the CLI lands). */
#include <stdio.h>
int main(void) { fprintf(stderr, "linewise: not yet\n"); return 2; }
