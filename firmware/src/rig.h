/* What every rig's firmware shares: the command loop of docs/protocol.md (HELLO, START,
 * STOP, STREAM, STATUS and the rig's own settings), and the run's telemetry, which the
 * control interrupt hands over a sample at a time and the main loop sends. */
#ifndef ARTICULA_RIG_H
#define ARTICULA_RIG_H

#include <stdint.h>

#define MAX_CHANNELS 8

/* A rig's program: its handshake and the hooks the command loop calls. */
struct rig {
    uint8_t kind;       /* 1 PneuNet, 2 six-chamber, 3 motor (protocol.py's RigKind) */
    uint32_t period_us; /* the sample period the handshake announces [µs] */
    uint8_t channel_count;
    const char *const (*channels)[2]; /* name and unit of each telemetry channel */
    /* A settings command (SET_GAINS, SET_REFERENCE, SET_OUTPUT, SET_DAMPING) at rest: 0 when
     * taken, else an error code of protocol.h with the reason in *why. */
    uint8_t (*configure)(uint8_t kind, const uint8_t *body, uint8_t length, const char **why);
    /* A run of `duration` [s] from rest: arm the control interrupt; 0 or an error code. */
    uint8_t (*start)(float duration, const char **why);
    /* Actuators off and the control interrupt disarmed (a run ends or is stopped). */
    void (*stop)(void);
    /* Optional: a sample's values made ready to send, off the control step (e.g. raw
     * counts into units); NULL sends them as the interrupt gave them. */
    void (*format)(float *values);
    /* Optional: work the main loop does for the coming control steps; NULL for none. */
    void (*background)(void);
};

/* Announce the rig (INFO, unasked), then answer commands and send the runs' telemetry; never
 * returns. */
void rig_serve(const struct rig *rig);
/* From the control interrupt: one sample of the run (channel_count values). */
void rig_sample(const float *values);
/* From the control interrupt: the run is over (after its last sample). */
void rig_done(void);
/* The ADC on analog input `channel` (AVCC reference, 125 kHz clock, its interrupt on), with
 * its first, long conversion started now, so it is over (and ignored) before any run. */
void adc_start(uint8_t channel);

/* The little-endian float32 at body[offset] (AVR floats are IEEE-754 single, little-endian). */
float read_float(const uint8_t *body, uint8_t offset);

#endif
