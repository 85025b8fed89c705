/* The dual-motor rig's firmware (chapter 4): the 1 kHz current loop on the primary motor and
 * the speed loop on the load motor, as articula's emulated rig runs them (rigs/motor.py,
 * loops/motor_current.py), in float32.
 *
 * Each millisecond Timer1 starts a conversion of the ACS712 on A1; its completion interrupt
 * takes the code and the encoder's count and runs the control step, with interrupts on (the
 * UART is served meanwhile, and the step's timing does not depend on what the main loop is
 * doing): the moving average (4.17), the PI + feed-forward
 * (4.13)-(4.14) and the duty (4.15)-(4.16) to Timer3's 8-bit PWM on D5 (ENA) with the
 * H-bridge's direction on D24/D25; the speed loop (4.12) on the encoder's counts (D2/D3, both edges of both
 * channels) drives D6 (ENB, Timer4) and D26/D27. Safe state: both enables off the PWM and
 * low, IN1-IN4 low (both bridges off). Pins: README's wiring table. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <string.h>
#include <util/atomic.h>

#include "probe.h"
#include "protocol.h"
#include "rig.h"
#include "uart.h"

RIG_PROGRAM("motor");

#define DT 0.001f            /* [s] the control period */
#define TICKS 16000          /* CPU cycles per period at 16 MHz */
#define V_MAX 12.0f          /* [V] the H-bridge's supply */
#define PWM_LEVELS 256.0f    /* 8-bit duty register */
#define MOTOR_R 8.35f        /* [Ω] Table 4.2, for the feed-forward (4.13) */
#define MOTOR_K 0.4485f      /* [V·s/rad] Table 4.2 */
#define SENSITIVITY 0.185f   /* [V/A] ACS712-5A */
#define ZERO_VOLTAGE 2.5f    /* [V] its output at 0 A */
#define ADC_VREF 5.0f        /* [V] AVCC */
#define ENCODER_CPR 375      /* counts per revolution (both edges of both channels) */
#define ENCODER_WINDOW 50    /* periods the speed is measured over */
#define MAX_ORDER 100        /* the moving average's longest window (RAM: 2 bytes each) */
#define SHAPE_CURRENT 4      /* programs.py's Shape.CURRENT */

static const char *const channels[][2] = {
    {"i_ref", "A"}, {"i_meas", "A"}, {"i_fb", "A"}, {"omega_meas", "rad/s"},
    {"v1", "V"},    {"duty1", "counts"}, {"v2", "V"}};

/* Settings: the gains (SET_GAINS) and the reference program (SET_REFERENCE). */
static float kp = 10.0f, ki = 100.0f, kp_speed = 5.0f, ki_speed = 10.0f;
static uint8_t order = 1;
static float current = 1.0f, amplitude = 0.0f, frequency = 0.0f, speed = 5.0f;

/* The run. */
static uint32_t n, steps;
/* The PI loops in PWM counts (the duty's V_MAX / 256 volts a count folded into the gains,
 * one product a step less): the integrals, and the gains times that scale (the integral
 * gains times the period too). */
static float integral, integral_speed;
static float kp_c, ki_dt_c, kp_speed_c, ki_speed_dt_c;
/* i_fb = code sum · fb_scale + fb_offset; fb_offset grows by fb_step until the filter fills */
static float fb_scale, fb_offset, fb_step;
static uint8_t filled;                       /* samples in the moving average so far */
static float speed_scale[ENCODER_WINDOW + 1]; /* rad/s per count over 1-50 periods */
/* The reference's sinusoid amplitude · sin(θ n), θ = frequency · DT, advanced a step at a time
 * by Minsky's recurrence x -= e y, y += e x with e = 2 sin(θ/2): two products a step instead
 * of a sinf; the map preserves area, so float32 rounding neither grows nor shrinks the
 * amplitude (over 60 s its error stays below 1e-3 of the amplitude up to 1000 rad/s; a
 * rotation's is about twice that). With y = 0 and x = amplitude · cos(θ/2) at the start, y is
 * exactly amplitude · sin(θ n). */
static float ref_x, ref_y, ref_e;
/* The run's outputs may be driven (live: safe() ends it); a control step is under way
 * (in_step); a conversion ended while one was (missed: the run ends). */
static volatile uint8_t live, in_step, missed;
static void safe(void);
static const float amps_per_code = ADC_VREF / 1024.0f / SENSITIVITY;
static const float amps_at_zero = (0.5f * ADC_VREF / 1024.0f - ZERO_VOLTAGE) / SENSITIVITY;
static uint16_t codes[MAX_ORDER];
static uint32_t code_sum;
static uint8_t code_slot;
static int32_t counts[ENCODER_WINDOW];
static uint8_t count_slot;
static volatile int32_t encoder;

/* Quadrature, both edges of both channels: A changing to differ from B is a step forward. */
ISR(INT4_vect) {
    uint8_t pins = PINE;
    encoder += ((pins >> PE4) & 1) != ((pins >> PE5) & 1) ? 1 : -1;
}

ISR(INT5_vect) {
    uint8_t pins = PINE;
    encoder += ((pins >> PE4) & 1) == ((pins >> PE5) & 1) ? 1 : -1;
}

/* The signed duty of (4.15)-(4.16) for a command in counts (volts · 256 / V_MAX). */
static int16_t duty(float command) {
    union {
        float value;
        uint32_t bits;
    } counts = {command};
    /* Past 255 the register saturates (4.16); the test is on the float's bits (a positive
     * float orders as its bits do), which also keeps the conversion below in range. */
    if ((counts.bits & 0x7FFFFFFFul) >= 0x437F0000ul) /* 255.0f */
        return counts.bits >> 31 ? -255 : 255;
    return (int16_t)counts.value; /* truncation: floor of the magnitude, sign kept */
}

/* The H-bridge: duty into the PWM register, sign onto the two direction pins (bit `in1`). */
static void drive(volatile uint8_t *ocr, uint8_t in1, int16_t counts) {
    *ocr = (uint8_t)(counts < 0 ? -counts : counts);
    uint8_t pins = PORTA & (uint8_t)~(3 << in1);
    if (counts > 0) pins |= (uint8_t)(1 << in1);
    else if (counts < 0) pins |= (uint8_t)(2 << in1);
    PORTA = pins;
}

/* An integer in a float's slot (its first two bytes), for the telemetry to convert. */
static void put_raw(float *slot, int16_t value) { memcpy(slot, &value, sizeof value); }

/* An integer the control step left in a float's slot (its first two bytes). */
static float raw_at(const float *slot) {
    int16_t value;
    memcpy(&value, slot, sizeof value);
    return value;
}

ISR(TIMER1_COMPA_vect) {
    probe_busy();
    ADCSRA |= _BV(ADSC); /* the ACS712 on A1 */
    probe_idle();
}

/* The control step (4.12)-(4.17) for the sample `code`, `count`, with interrupts on; its
 * outputs written at once, with interrupts off, and only while the run is live (safe()
 * ends that: a step that was under way when the outputs went safe does not drive them). */
static void step(uint16_t code, int32_t count) {
    /* (4.17) as a mean over `order` samples, those before the run counting as 0 A: the sum
     * of the codes, turned into amperes once (the ADC's reading is affine in its code). */
    code_sum = code_sum - codes[code_slot] + code; /* in 32 bits: int is 16 on the AVR */
    codes[code_slot] = code;
    code_slot = (uint8_t)(code_slot + 1 == order ? 0 : code_slot + 1);
    if (filled < order) filled++, fb_offset += fb_step;
    float i_fb = (float)code_sum * fb_scale + fb_offset;

    int32_t old = n >= ENCODER_WINDOW ? counts[count_slot] : 0;
    counts[count_slot] = count;
    count_slot = (uint8_t)(count_slot + 1 == ENCODER_WINDOW ? 0 : count_slot + 1);
    uint8_t span = n == 0 ? 1 : (n < ENCODER_WINDOW ? (uint8_t)n : ENCODER_WINDOW);
    float omega_meas = (float)(count - old) * speed_scale[span];

    float i_ref = current + ref_y; /* amplitude · sin(frequency · n · DT) */
    ref_x -= ref_e * ref_y;
    ref_y += ref_e * ref_x;
    float error = i_ref - i_fb; /* (4.14) with e_I = i_ss - i (docs/deviations.md) */
    integral += ki_dt_c * error; /* the feed-forward (4.13) plus ki·∫e dt */
    int16_t duty1 = duty(kp_c * error + integral);
    /* (4.12) on the load motor, wired with reversed polarity: a positive V2 brakes. */
    float error_speed = speed - omega_meas;
    integral_speed += ki_speed_dt_c * error_speed;
    int16_t duty2 = duty(-(kp_speed_c * error_speed + integral_speed));
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        if (live) {
            drive(&OCR3AL, PA2, duty1);
            drive(&OCR4AL, PA4, duty2);
        }
    }

    /* Raw where a conversion can wait for the telemetry (format_sample): the ADC code and
     * the duties as integers in their channels' slots. */
    float *values = rig_slot();
    values[0] = i_ref, values[2] = i_fb, values[3] = omega_meas;
    put_raw(values + 1, (int16_t)code);
    put_raw(values + 5, duty1);
    put_raw(values + 6, duty2);
    rig_sample();
    if (++n >= steps) {
        safe(); /* the last step: outputs off now */
        rig_done();
    }
}

/* The conversion is done: the control step on its sample, with interrupts on from the
 * interrupt's first instruction (ISR_NOBLOCK: its prologue saves every register a call may
 * clobber, some 70 cycles, which with interrupts off would hold the UART's receive interrupt
 * up by about a byte's time), the encoder's count read atomically. The next conversion ends
 * a period later; one that ends while a step is still under way (it overran its period) is
 * not a sample: the run ends. */
ISR(ADC_vect, ISR_NOBLOCK) {
    probe_busy();
    if (in_step) {
        missed = 1;
        return;
    }
    in_step = 1;
    uint16_t code = ADC;
    int32_t count;
    ATOMIC_BLOCK(ATOMIC_FORCEON) { count = encoder; }
    step(code, count);
    in_step = 0;
    probe_idle();
}

/* The main loop's check of the run: a step that overran its period ends it. */
static const char *control(void) { return missed ? "a control step missed its 1 ms period" : 0; }

/* Off the control step: a sample's ADC code in amperes and its duties in counts and volts. */
static void format_sample(float *values) {
    values[1] = raw_at(values + 1) * amps_per_code + amps_at_zero; /* mid-step reconstruction */
    values[5] = raw_at(values + 5);
    values[4] = values[5] * (V_MAX / PWM_LEVELS);
    values[6] = raw_at(values + 6) * (V_MAX / PWM_LEVELS);
}

static uint8_t is_finite(float value) { return isfinite(value); }

static uint8_t configure(uint8_t kind, const uint8_t *body, uint8_t length, const char **why) {
    if (kind == SET_GAINS) {
        if (length != 20) {
            *why = "SET_GAINS for the motor rig takes 5 reals";
            return BAD_FRAME;
        }
        float g[5];
        for (uint8_t k = 0; k < 5; k++) g[k] = read_float(body, (uint8_t)(4 * k));
        if (!(g[0] >= 0 && g[1] >= 0 && g[3] >= 0 && g[4] >= 0) || !is_finite(g[0] + g[1] + g[3] + g[4])
            || !(g[2] >= 1 && g[2] <= MAX_ORDER) || g[2] != floorf(g[2])) {
            *why = "SET_GAINS: gains must be >= 0 and the filter order 1-100 on this firmware";
            return BAD_VALUE;
        }
        kp = g[0], ki = g[1], order = (uint8_t)g[2], kp_speed = g[3], ki_speed = g[4];
        return 0;
    }
    if (kind == SET_REFERENCE) {
        if (length != 18 || body[0] != SHAPE_CURRENT || body[1] != 4) {
            *why = "the motor rig runs a current program";
            return BAD_VALUE;
        }
        float v[4];
        for (uint8_t k = 0; k < 4; k++) v[k] = read_float(body, (uint8_t)(2 + 4 * k));
        if (!is_finite(v[0] + v[1] + v[2] + v[3])) {
            *why = "SET_REFERENCE: numbers must be finite";
            return BAD_VALUE;
        }
        current = v[0], amplitude = v[1], frequency = v[2], speed = v[3];
        return 0;
    }
    *why = "the motor rig does not take this command";
    return UNKNOWN;
}

static uint8_t start(float duration, const char **why) {
    float periods = duration / DT;
    if (!(periods >= 0.5f && periods < 4.0e9f)) {
        *why = "the run's duration must be > 0";
        return BAD_VALUE;
    }
    steps = (uint32_t)lroundf(periods);
    n = 0;
    const float scale = PWM_LEVELS / V_MAX; /* counts per volt */
    integral = (current * MOTOR_R + MOTOR_K * speed) * scale; /* (4.13), the feed-forward */
    integral_speed = 0.0f;
    kp_c = kp * scale, ki_dt_c = ki * DT * scale;
    kp_speed_c = kp_speed * scale, ki_speed_dt_c = ki_speed * DT * scale;
    fb_scale = amps_per_code / order;
    fb_step = amps_at_zero / order;
    fb_offset = 0.0f;
    filled = 0;
    ref_y = 0.0f;
    ref_x = amplitude * cosf(0.5f * frequency * DT);
    ref_e = 2.0f * sinf(0.5f * frequency * DT);
    for (uint8_t k = 0; k < MAX_ORDER; k++) codes[k] = 0;
    code_sum = 0;
    code_slot = count_slot = 0;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        encoder = 0;
        missed = in_step = 0;
        live = 1;
        TCCR3A |= _BV(COM3A1); /* the enables back on their PWM, at duty 0 */
        TCCR4A |= _BV(COM4A1);
        ADCSRA |= _BV(ADIF) | _BV(ADIE); /* a conversion that ended at rest is not a sample */
        TCNT1 = 0;
        TIFR1 = _BV(OCF1A);
        TIMSK1 = _BV(OCIE1A);
    }
    return 0;
}

/* Both H-bridges off: no more control ticks or samples, the enables taken off the PWM and
 * driven low (a fast PWM at duty 0 still pulses once a cycle), the direction pins low; in one
 * atomic write of some 50 cycles (tools/interrupts_off.py). */
static void safe(void) {
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        TIMSK1 = 0;
        ADCSRA = (uint8_t)((ADCSRA & ~_BV(ADIE)) | _BV(ADIF)); /* ADIF: cleared by a 1 */
        live = 0;
        TCCR3A &= (uint8_t)~_BV(COM3A1);
        TCCR4A &= (uint8_t)~_BV(COM4A1);
        PORTE &= (uint8_t)~_BV(PE3);
        PORTH &= (uint8_t)~_BV(PH3);
        PORTA &= (uint8_t)~(_BV(PA2) | _BV(PA3) | _BV(PA4) | _BV(PA5));
        OCR3AL = 0;
        OCR4AL = 0;
    }
}

/* GET: the gains and the reference as SET_GAINS and SET_REFERENCE carry them. */
static uint8_t setting(uint8_t kind, uint8_t *body) {
    if (kind == SET_GAINS) {
        const float g[5] = {kp, ki, order, kp_speed, ki_speed};
        for (uint8_t k = 0; k < 5; k++) write_float(body, (uint8_t)(4 * k), g[k]);
        return 20;
    }
    if (kind == SET_REFERENCE) {
        const float v[4] = {current, amplitude, frequency, speed};
        body[0] = SHAPE_CURRENT;
        body[1] = 4;
        for (uint8_t k = 0; k < 4; k++) write_float(body, (uint8_t)(2 + 4 * k), v[k]);
        return 18;
    }
    return 0xFF;
}

static const struct rig motor = {.kind = 3, .period_us = 1000, .channel_count = 7,
                                 .channels = channels, .configure = configure,
                                 .setting = setting, .start = start, .safe = safe,
                                 .control = control, .format = format_sample};

int main(void) {
    uart_init();
    for (uint8_t span = 1; span <= ENCODER_WINDOW; span++)
        speed_scale[span] = 2.0f * (float)M_PI / ENCODER_CPR / (span * DT);
    DDRA |= _BV(PA2) | _BV(PA3) | _BV(PA4) | _BV(PA5); /* IN1-IN4: D24-D27 */
    DDRE |= _BV(PE3);                                 /* ENA: D5, OC3A */
    DDRH |= _BV(PH3);                                 /* ENB: D6, OC4A */
    TCCR3A = _BV(WGM30); /* fast PWM, 8 bit, 62.5 kHz; on the pins during runs only */
    TCCR3B = _BV(WGM32) | _BV(CS30);
    TCCR4A = _BV(WGM40);
    TCCR4B = _BV(WGM42) | _BV(CS40);
    OCR1A = TICKS - 1; /* TOP first: the timer starts with its clock (simavr reads TOP then) */
    TCCR1B = _BV(WGM12) | _BV(CS10); /* CTC: the 1 kHz control tick */
    adc_start(1); /* the ACS712 on A1 */
    EICRB = _BV(ISC40) | _BV(ISC50); /* D2/D3 (INT4/INT5): any edge */
    EIMSK = _BV(INT4) | _BV(INT5);
    rig_serve(&motor);
}
