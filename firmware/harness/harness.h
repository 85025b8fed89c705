/* What the harness's two parts share: harness.c (the board, its plant, its life) and line.c
 * (the host's line: the pty, UART0 as the chip's USART receives, the trace). */
#ifndef ARTICULA_HARNESS_H
#define ARTICULA_HARNESS_H

#include <stdint.h>
#include <stdio.h>

#include "sim_avr.h"

#define CYCLES_PER_MS 16000

extern avr_t *avr;
extern int running;   /* a run goes on (the firmware's probe, probe.h) */
extern FILE *trace;   /* --trace: the pins and the line's frames over time; NULL without */

/* The trace's line for an event at the current cycle: "<what> <cycle> <text>". */
void trace_event(const char *what, const char *text);
/* With --plant: end when the plant process has (its end of standard input closed). */
void exit_without_plant(void);

/* The host's line. line_open: the pty (its path into `path`), UART0's receive buffer and
 * transmitter hooked; line_reset: after a board reset (the USART forgets what it held). */
void line_open(char *path, size_t size);
void line_reset(void);
/* Bytes still to go to the host (the start-up waits for its INFO to be out). */
uint32_t line_to_host(void);
/* The cycle the host's last byte began on the line. */
avr_cycle_count_t line_heard(void);
/* Serve the pty from now on (again after a reset: simavr drops every cycle timer). */
void line_serve(void);

#endif
