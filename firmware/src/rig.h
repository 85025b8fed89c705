/* What every rig's firmware shares: the command loop of docs/protocol.md (HELLO, START,
 * STOP, STREAM, STATUS, GET and the rig's own settings), the run's life and its one safe
 * state, the watchdog, the host timeout and a millisecond clock.
 *
 * No section with interrupts off (an interrupt's own, a cli's up to its sei or SREG restore)
 * is longer than a byte's time at 1 Mbaud, 160 cycles, so the USART's 2-byte buffer never
 * overruns: interrupts sample with interrupts off; a rig's control step then runs with
 * interrupts on (in its sample's interrupt, re-enabled, or in the main loop), and its timing
 * does not depend on what the main loop is doing. Outputs are written in short atomic
 * writes and only while the run is live. Every end of a run (DONE, STOP, an error, the
 * host's silence, the watchdog, a reset) puts the outputs in the rig's safe state through one
 * function. tools/interrupts_off.py bounds every such section from the ELF; the harness's
 * trace measures them (docs/guides/firmware.md). */
#ifndef ARTICULA_RIG_H
#define ARTICULA_RIG_H

#include <stdint.h>

#define MAX_CHANNELS 8

/* The program's name in the ELF's .articula section, which is not loaded into the chip:
 * articula checks it before the emulator runs a file (rigs/elf.py). */
#define RIG_PROGRAM(name) \
    __asm__(".pushsection .articula,\"\",@progbits\n.asciz \"articula program=" name \
            "\"\n.popsection")

/* A rig's program: its handshake and the hooks the command loop calls. */
struct rig {
    uint8_t kind;       /* 1 PneuNet, 2 six-chamber, 3 motor (protocol.py's RigKind) */
    uint32_t period_us; /* the sample period the handshake announces [µs] */
    uint8_t channel_count;
    const char *const (*channels)[2]; /* name and unit of each telemetry channel */
    /* A settings command (SET_GAINS, SET_REFERENCE, SET_OUTPUT, SET_DAMPING) at rest: 0 when
     * taken, else an error code of protocol.h with the reason in *why. */
    uint8_t (*configure)(uint8_t kind, const uint8_t *body, uint8_t length, const char **why);
    /* GET: the body of the setting `kind` (a SET_ command) as that command carries it, into
     * body (up to MAX_FRAME - 7 bytes); its length, or 0xFF for a setting this rig has not. */
    uint8_t (*setting)(uint8_t kind, uint8_t *body);
    /* A run of `duration` [s] from rest: its outputs and control interrupts armed in one
     * short atomic write, the rest computed with interrupts on; 0 or an error code. */
    uint8_t (*start)(float duration, const char **why);
    /* The safe state: outputs off (as docs/protocol.md states per rig) and the control
     * interrupts disarmed, their pending flags cleared, in one short atomic write (interrupts
     * off for well under 160 cycles), so that no interrupt runs between its writes and
     * nothing it disarms fires after. Called with interrupts on or off: at start-up, at every
     * end of a run, from the watchdog's interrupt. */
    void (*safe)(void);
    /* The run's main-loop work, called over and over while it goes on: work the interrupts
     * flagged (rig_event), and the run's own checks; NULL, or a reason that ends the run in
     * the safe state (an ERROR names it). */
    const char *(*control)(void);
    /* Optional: a sample's values made ready to send, off the control step (e.g. raw
     * counts into units); NULL sends them as the control step gave them. */
    void (*format)(float *values);
};

/* Set by a rig's interrupt when it has flagged work for control(): the main loop does not
 * sleep while it is set. */
extern volatile uint8_t rig_event;

/* Announce the rig (INFO, unasked, with why it started), then answer commands and run;
 * never returns. */
void rig_serve(const struct rig *rig);
/* From the control step (an interrupt's or control()): where the run's next sample goes (channel_count values), written in
 * place; rig_sample() then takes it. When the telemetry is behind and its ring full, the
 * slot is a scratch one and the sample is not sent (the host sees the gap). */
float *rig_slot(void);
/* From the control step: the sample in rig_slot() is the run's next. */
void rig_sample(void);
/* From the control step: the run is over (after its last sample, outputs safe). */
void rig_done(void);
/* Milliseconds since start-up, wrapping at 65536 (Timer0's 1 kHz tick). */
uint16_t rig_clock_ms(void);
/* The ADC on analog input `channel` (AVCC reference, 125 kHz clock), with its first, long
 * conversion started now, so it is over (and ignored) before any run. Its interrupt stays
 * off until a run's start() turns it on. */
void adc_start(uint8_t channel);

/* The little-endian float32 at body[offset] (AVR floats are IEEE-754 single, little-endian). */
float read_float(const uint8_t *body, uint8_t offset);
/* `value` as little-endian float32 into body[offset..offset + 3]. */
void write_float(uint8_t *body, uint8_t offset, float value);

#endif
