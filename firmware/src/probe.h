/* The emulator's test port: writes to the general-purpose I/O registers GPIOR0-1, which a
 * real board ignores and the simavr harness (harness/harness.c) watches. They tell the
 * simulated plant when a run starts (and with which noise seed) and ends, and mark the control step's
 * first and last instruction so the harness counts its CPU cycles. One OUT instruction each. */
#ifndef ARTICULA_PROBE_H
#define ARTICULA_PROBE_H

#include <avr/io.h>
#include <stdint.h>

enum probe_mark { PROBE_RUN = 1, PROBE_BUSY = 2, PROBE_IDLE = 3, PROBE_END = 4 };

/* A run starts from rest: the seed's four bytes (least significant first), then the mark. */
static inline void probe_run(uint32_t seed) {
    for (uint8_t k = 0; k < 4; k++) GPIOR1 = (uint8_t)(seed >> (8 * k));
    GPIOR0 = PROBE_RUN;
}

/* The control step's work begins / ends (an interrupt's body; it may come in pieces). */
static inline void probe_busy(void) { GPIOR0 = PROBE_BUSY; }
static inline void probe_idle(void) { GPIOR0 = PROBE_IDLE; }
/* The run is over or stopped. */
static inline void probe_end(void) { GPIOR0 = PROBE_END; }

#endif
