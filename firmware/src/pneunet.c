/* The PneuNet rig's firmware (chapter 2): the PID family on the flex sensor at the valve's
 * 30 Hz PWM, as articula's emulated rig runs it (rigs/pneunet.py, control/pid.py), in
 * float32.
 *
 * Timer1 runs the valve's PWM on D11 (OC1A): 8333 ticks of 4 µs, 33.332 ms (the book's
 * 1/30 s to 0.01 %). At each period's start its overflow interrupt starts a conversion of
 * the flex sensor's divider on A0; the conversion's interrupt takes the code and evaluates,
 * with interrupts on, the PID (2.2)-(2.4) with gains scheduled on the
 * reference (constant, piecewise or fuzzy), anti-windup at the 0-255 range, and writes the
 * period's duty. The pump on D8 runs during a run. Safe state: the valve's pin off the PWM
 * and low (closed), the pump off. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <util/atomic.h>

#include "probe.h"
#include "protocol.h"
#include "rig.h"
#include "uart.h"

RIG_PROGRAM("pneunet");

#define RATE_HZ 30.0f              /* the valve's PWM frequency */
#define DT (1.0f / RATE_HZ)        /* [s] */
#define TICKS 8333                 /* Timer1 ticks per period (prescaler 64) */
#define SENSOR_ZERO 1.0f           /* [V] the divider at 0° */
#define SENSOR_GAIN (2.5f / (float)M_PI_2) /* [V/rad]: 2.5 V over 0-90° */
#define ADC_VREF 5.0f              /* [V] */
#define DEG_PER_RAD (180.0f / (float)M_PI)
#define MAX_ROWS 8                 /* gain-schedule rows */
#define MAX_LEVELS 60              /* levels of a steps program */
enum shape { CONSTANT = 0, STEPS = 1, SINUSOID = 2 }; /* programs.py's Shape */
enum schedule { FIXED = 0, PIECEWISE = 1, FUZZY = 2 }; /* "constant", "piecewise", "fuzzy" */

static const char *const channels[][2] = {{"reference", "deg"}, {"angle", "deg"},
                                          {"pwm", "counts"}};

/* Settings: the gain schedule (rows of K_p, K_i, K_d at their points), the reference
 * program, an open-loop PWM count (SET_OUTPUT; negative: closed loop). */
static uint8_t schedule = FIXED, rows = 1;
static float gains[MAX_ROWS][3] = {{1.0f, 1.0f, 0.0f}};
static float points[MAX_ROWS];
static uint8_t shape = CONSTANT, levels = 1;
static float values[MAX_LEVELS + 1]; /* constant: value; steps: hold, levels; sinusoid */
static float open_loop = -1.0f;

/* The run. */
static uint32_t n, steps;
static float integral, last_error;
/* The run's outputs may be driven (live: safe() ends it); a step is under way (in_step); a
 * conversion ended while one was (missed: the run ends). */
static volatile uint8_t live, in_step, missed;
static void safe(void);

/* The reference at step n (programs.py's Program.at). */
static float reference_at(uint32_t k) {
    if (shape == CONSTANT) return values[0];
    if (shape == SINUSOID) /* offset - amplitude cos(2π f t): from rest */
        return values[0] - values[1] * cosf(2.0f * (float)M_PI * values[2] * (float)k * DT);
    /* steps: level floor(t / hold), the last held to the end; in periods, t = n / 30 s */
    float index = floorf((float)k / (values[0] * RATE_HZ) + 1e-6f);
    return values[1 + (index < levels - 1 ? (uint8_t)index : levels - 1)];
}

/* Gain j (K_p, K_i, K_d) at reference r: GainSchedule.__call__. */
static float gain(uint8_t j, float r) {
    if (schedule == FIXED) return gains[0][j];
    uint8_t k = 0;
    if (schedule == PIECEWISE) { /* the subranges meet half-way between points */
        while (k + 1 < rows && r >= 0.5f * (points[k] + points[k + 1])) k++;
        return gains[k][j];
    }
    if (r <= points[0]) return gains[0][j]; /* fuzzy: linear between points, flat beyond */
    if (r >= points[rows - 1]) return gains[rows - 1][j];
    while (r > points[k + 1]) k++;
    float w = (r - points[k]) / (points[k + 1] - points[k]);
    return gains[k][j] + w * (gains[k + 1][j] - gains[k][j]);
}

ISR(TIMER1_OVF_vect) {
    probe_busy();
    ADCSRA |= _BV(ADSC); /* the flex sensor on A0 */
    probe_idle();
}

/* The PID step (2.2)-(2.4) for the sample `code`, with interrupts on; its duty written with
 * interrupts off, and only while the run is live (safe() ends that: a step under way when
 * the outputs went safe does not open the valve again). */
static void step(uint16_t code) {
    const float deg_per_code = ADC_VREF / 1024.0f / SENSOR_GAIN * DEG_PER_RAD;
    const float deg_at_zero = (0.5f * ADC_VREF / 1024.0f - SENSOR_ZERO) / SENSOR_GAIN * DEG_PER_RAD;
    float angle = (float)code * deg_per_code + deg_at_zero; /* mid-step reconstruction */
    float reference = reference_at(n);
    float u;
    if (open_loop >= 0.0f) {
        u = open_loop;
    } else {
        float error = reference - angle; /* e[n] = θ_r − θ[n] */
        float sum = integral, derivative = 0.0f;
        if (n > 0) { /* the first sample has no Δt: nothing to integrate or differentiate */
            sum = integral + error * DT;           /* Σ e[i] Δt, (2.2) */
            derivative = (error - last_error) / DT; /* Δe/Δt, (2.2) */
        }
        float kp = gain(0, reference), ki = gain(1, reference), kd = gain(2, reference);
        float proportional = kp * error + kd * derivative;
        u = proportional + ki * sum; /* u = K(θ_r)ᵀ E, (2.3)-(2.4) */
        /* Anti-windup: the old sum stays where integrating would push further past a limit. */
        if ((u > 255.0f && ki * error > 0.0f) || (u < 0.0f && ki * error < 0.0f))
            u = proportional + ki * integral;
        else
            integral = sum;
        last_error = error;
    }
    uint8_t count = u >= 255.0f ? 255 : (u <= 0.0f ? 0 : (uint8_t)u); /* floor in [0, 255] */
    uint16_t ticks = (uint16_t)(((uint32_t)count * TICKS + 127) / 255); /* the period's duty */
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        if (live) OCR1A = ticks; /* the period's duty, only while the run is live */
    }
    float *sample = rig_slot();
    sample[0] = reference, sample[1] = angle, sample[2] = count;
    rig_sample();
    if (++n >= steps) {
        safe(); /* the last step: valve and pump off */
        rig_done();
    }
}

/* The conversion is done: the PID on its sample, with interrupts on from the interrupt's
 * first instruction (ISR_NOBLOCK: its prologue saves every register a call may clobber, some
 * 70 cycles, which with interrupts off would hold the UART's receive interrupt up by about a
 * byte's time). The next conversion ends a period later; one that ends while a step is still
 * under way (it overran its period) is not a sample: the run ends. */
ISR(ADC_vect, ISR_NOBLOCK) {
    probe_busy();
    if (in_step) {
        missed = 1;
        return;
    }
    in_step = 1;
    step(ADC);
    in_step = 0;
    probe_idle();
}

/* The main loop's check of the run: a step that overran its period ends it. */
static const char *control(void) { return missed ? "a control step missed its 33 ms period" : 0; }

static uint8_t configure(uint8_t kind, const uint8_t *body, uint8_t length, const char **why) {
    if (kind == SET_GAINS) {
        uint8_t count = length >= 2 ? body[1] : 0;
        if (length < 2 || body[0] > FUZZY || length != 2 + 16 * count) {
            *why = "SET_GAINS does not decode";
            return BAD_FRAME;
        }
        if (count < 1 || count > MAX_ROWS || (body[0] == FIXED && count != 1)) {
            *why = "SET_GAINS: one row for constant gains, up to 8 for a schedule";
            return BAD_VALUE;
        }
        for (uint8_t k = 0; k < count; k++) {
            for (uint8_t j = 0; j < 3; j++) gains[k][j] = read_float(body, (uint8_t)(2 + 16 * k + 4 * j));
            points[k] = read_float(body, (uint8_t)(2 + 16 * k + 12));
        }
        schedule = body[0], rows = count;
        return 0;
    }
    if (kind == SET_REFERENCE) {
        uint8_t count = length >= 2 ? body[1] : 0;
        if (length < 2 || length != 2 + 4 * count) {
            *why = "SET_REFERENCE does not decode";
            return BAD_FRAME;
        }
        uint8_t ok = (body[0] == CONSTANT && count == 1) || (body[0] == SINUSOID && count == 3) ||
                     (body[0] == STEPS && count >= 2 && count <= MAX_LEVELS + 1);
        if (!ok) {
            *why = "the PneuNet rig runs a constant, steps or sinusoid program";
            return BAD_VALUE;
        }
        for (uint8_t k = 0; k < count; k++) values[k] = read_float(body, (uint8_t)(2 + 4 * k));
        if (body[0] == STEPS && !(values[0] > 0.0f)) {
            *why = "SET_REFERENCE: the hold time must be > 0";
            return BAD_VALUE;
        }
        shape = body[0], levels = (uint8_t)(count - 1);
        return 0;
    }
    if (kind == SET_OUTPUT) {
        float value = length == 5 ? read_float(body, 1) : -1.0f;
        if (length != 5 || body[0] != 0 || !(value >= 0.0f && value <= 255.0f)) {
            *why = "SET_OUTPUT: channel 0 takes a PWM count in 0-255";
            return BAD_VALUE;
        }
        open_loop = value;
        return 0;
    }
    *why = "the PneuNet rig does not take this command";
    return UNKNOWN;
}

static uint8_t start(float duration, const char **why) {
    float periods = duration * RATE_HZ;
    if (!(periods >= 0.5f && periods < 4.0e9f)) {
        *why = "the run's duration must be > 0";
        return BAD_VALUE;
    }
    steps = (uint32_t)lroundf(periods);
    n = 0;
    integral = last_error = 0.0f;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        missed = in_step = 0;
        live = 1;
        OCR1A = 0;
        TCCR1A |= _BV(COM1A1); /* the valve back on its PWM, at duty 0 */
        PORTH |= _BV(PH5);     /* the pump */
        ADCSRA |= _BV(ADIF) | _BV(ADIE); /* a conversion that ended at rest is not a sample */
        TCNT1 = 0;
        TIFR1 = _BV(TOV1);
        TIMSK1 = _BV(TOIE1);
    }
    return 0;
}

/* Valve closed, pump off: no more control ticks or samples, the valve's pin taken off the PWM
 * and driven low (a fast PWM at duty 0 still pulses once a period); in one atomic write of
 * some 40 cycles (tools/interrupts_off.py). An open-loop output (SET_OUTPUT) holds for one
 * run only. */
static void safe(void) {
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        TIMSK1 = 0;
        ADCSRA = (uint8_t)((ADCSRA & ~_BV(ADIE)) | _BV(ADIF)); /* ADIF: cleared by a 1 */
        live = 0;
        TCCR1A &= (uint8_t)~_BV(COM1A1);
        PORTB &= (uint8_t)~_BV(PB5);
        PORTH &= (uint8_t)~_BV(PH5);
        OCR1A = 0;
    }
    open_loop = -1.0f;
}

/* GET: the gains, the reference and the open-loop output as their SET_ commands carry them
 * (the output -1 when there is none). */
static uint8_t setting(uint8_t kind, uint8_t *body) {
    uint8_t n = 0;
    if (kind == SET_GAINS) {
        body[n++] = schedule;
        body[n++] = rows;
        for (uint8_t k = 0; k < rows; k++) {
            for (uint8_t j = 0; j < 3; j++, n += 4) write_float(body, n, gains[k][j]);
            write_float(body, n, points[k]);
            n += 4;
        }
        return n;
    }
    if (kind == SET_REFERENCE) {
        uint8_t count = shape == STEPS ? (uint8_t)(levels + 1) : (shape == SINUSOID ? 3 : 1);
        body[n++] = shape;
        body[n++] = count;
        for (uint8_t k = 0; k < count; k++, n += 4) write_float(body, n, values[k]);
        return n;
    }
    if (kind == SET_OUTPUT) {
        body[0] = 0;
        write_float(body, 1, open_loop);
        return 5;
    }
    return 0xFF;
}

static const struct rig pneunet = {.kind = 1, .period_us = 33333, .channel_count = 3,
                                   .channels = channels, .configure = configure,
                                   .setting = setting, .start = start, .safe = safe,
                                   .control = control};

int main(void) {
    uart_init();
    DDRB |= _BV(PB5); /* the valve: D11, OC1A */
    DDRH |= _BV(PH5); /* the pump: D8 */
    ICR1 = TICKS - 1; /* TOP first: the timer starts with its clock (simavr reads TOP then) */
    TCCR1A = _BV(WGM11); /* fast PWM, TOP = ICR1; on the valve's pin during runs only */
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11) | _BV(CS10); /* 16 MHz / 64 */
    adc_start(0); /* the flex sensor on A0 */
    rig_serve(&pneunet);
}
