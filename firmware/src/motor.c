/* The dual-motor rig's firmware (chapter 4): the 1 kHz current loop on the primary motor and
 * the speed loop on the load motor, as articula's emulated rig runs them (rigs/motor.py,
 * loops/motor_current.py), in float32.
 *
 * Each millisecond Timer1 starts a conversion of the ACS712 on A1; its completion interrupt
 * takes the moving average (4.17), the PI + feed-forward (4.13)-(4.14) and writes the duty
 * (4.15)-(4.16) to Timer3's 8-bit PWM on D5 (ENA) with the H-bridge's direction on D24/D25;
 * the speed loop (4.12) on the encoder's counts (D2/D3, both edges of both channels) drives
 * D6 (ENB, Timer4) and D26/D27. Pins: README's wiring table. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <util/atomic.h>

#include "probe.h"
#include "protocol.h"
#include "rig.h"
#include "uart.h"

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
static float integral, integral_speed;
static float ki_dt, ki_speed_dt; /* the integral gains times the period */
/* i_fb = code sum · fb_scale + fb_offset; fb_offset grows by fb_step until the filter fills */
static float fb_scale, fb_offset, fb_step;
static uint8_t filled;                       /* samples in the moving average so far */
static float speed_scale[ENCODER_WINDOW + 1]; /* rad/s per count over 1-50 periods */
/* The reference i_ref of step `reference_for` (its low byte) and the sin, cos of frequency ·
 * DT · that step, computed by the main loop ahead of the step; `step`: the next step's. */
static float reference, sin_t, cos_t, sin_step, cos_step;
static volatile uint8_t reference_for, step;
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

/* The signed duty of (4.15)-(4.16) for a commanded voltage [V]. */
static int16_t duty(float voltage) {
    union {
        float value;
        uint32_t bits;
    } counts = {voltage * (PWM_LEVELS / V_MAX)};
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

ISR(TIMER1_COMPA_vect) {
    probe_busy();
    ADCSRA |= _BV(ADSC); /* the ACS712 on A1; the loop runs when the conversion is done */
    probe_idle();
}

ISR(ADC_vect) {
    if (n >= steps) return; /* at rest (the first conversion after reset) */
    probe_busy();
    uint16_t code = ADC;
    /* (4.17) as a mean over `order` samples, those before the run counting as 0 A: the sum
     * of the codes, turned into amperes once (the ADC's reading is affine in its code). */
    code_sum = code_sum - codes[code_slot] + code; /* in 32 bits: int is 16 on the AVR */
    codes[code_slot] = code;
    code_slot = (uint8_t)(code_slot + 1 == order ? 0 : code_slot + 1);
    if (filled < order) filled++, fb_offset += fb_step;
    float i_fb = (float)code_sum * fb_scale + fb_offset;

    int32_t count = encoder;
    int32_t old = n >= ENCODER_WINDOW ? counts[count_slot] : 0;
    counts[count_slot] = count;
    count_slot = (uint8_t)(count_slot + 1 == ENCODER_WINDOW ? 0 : count_slot + 1);
    uint8_t span = n == 0 ? 1 : (n < ENCODER_WINDOW ? (uint8_t)n : ENCODER_WINDOW);
    float omega_meas = (float)(count - old) * speed_scale[span];

    /* The main loop has this step's reference ready; if it lags, it is computed here. */
    float i_ref = reference_for == (uint8_t)n
                      ? reference
                      : current + amplitude * sinf(frequency * ((float)n * DT));
    float error = i_ref - i_fb; /* (4.14) with e_I = i_ss - i (docs/deviations.md) */
    integral += ki_dt * error;  /* the feed-forward (4.13) plus ki·∫e dt */
    int16_t duty1 = duty(kp * error + integral);
    drive(&OCR3AL, PA2, duty1);
    /* (4.12) on the load motor, wired with reversed polarity: a positive V2 brakes. */
    float error_speed = speed - omega_meas;
    integral_speed += ki_speed_dt * error_speed;
    int16_t duty2 = duty(-(kp_speed * error_speed + integral_speed));
    drive(&OCR4AL, PA4, duty2);

    /* Raw where a conversion can wait for the main loop (format_sample). */
    float values[7] = {i_ref, code, i_fb, omega_meas, duty1, duty1, duty2};
    rig_sample(values);
    step = (uint8_t)++n;
    if (n >= steps) {
        TIMSK1 = 0;
        drive(&OCR3AL, PA2, 0);
        drive(&OCR4AL, PA4, 0);
        rig_done();
    }
    probe_idle();
}

/* Off the control step: a sample's ADC code in amperes and its duties in volts. */
static void format_sample(float *values) {
    values[1] = values[1] * amps_per_code + amps_at_zero; /* mid-step reconstruction */
    values[4] *= V_MAX / PWM_LEVELS;
    values[6] *= V_MAX / PWM_LEVELS;
}

/* Off the control step: the coming steps' reference, its sinusoid by rotation (4 products a
 * step instead of a sinf); float32 rounding drifts it by about 1e-4 of the amplitude over a
 * 6 s run. */
static void background(void) {
    while (reference_for != step) {
        float sin_next = sin_t * cos_step + cos_t * sin_step;
        cos_t = cos_t * cos_step - sin_t * sin_step;
        sin_t = sin_next;
        reference = current + amplitude * sin_t;
        reference_for++; /* one byte: the interrupt sees the old or the new step, whole */
    }
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
    integral = current * MOTOR_R + MOTOR_K * speed; /* (4.13), the constant feed-forward */
    integral_speed = 0.0f;
    ki_dt = ki * DT;
    ki_speed_dt = ki_speed * DT;
    fb_scale = amps_per_code / order;
    fb_step = amps_at_zero / order;
    fb_offset = 0.0f;
    filled = 0;
    step = reference_for = 0;
    sin_t = 0.0f;
    cos_t = 1.0f;
    reference = current;
    sin_step = sinf(frequency * DT);
    cos_step = cosf(frequency * DT);
    for (uint8_t k = 0; k < MAX_ORDER; k++) codes[k] = 0;
    code_sum = 0;
    code_slot = count_slot = 0;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { encoder = 0; }
    TCNT1 = 0;
    TIFR1 = _BV(OCF1A);
    TIMSK1 = _BV(OCIE1A);
    return 0;
}

static void stop(void) {
    TIMSK1 = 0;
    drive(&OCR3AL, PA2, 0);
    drive(&OCR4AL, PA4, 0);
}

static const struct rig motor = {.kind = 3, .period_us = 1000, .channel_count = 7,
                                 .channels = channels, .configure = configure, .start = start,
                                 .stop = stop, .format = format_sample,
                                 .background = background};

int main(void) {
    uart_init();
    for (uint8_t span = 1; span <= ENCODER_WINDOW; span++)
        speed_scale[span] = 2.0f * (float)M_PI / ENCODER_CPR / (span * DT);
    DDRA |= _BV(PA2) | _BV(PA3) | _BV(PA4) | _BV(PA5); /* IN1-IN4: D24-D27 */
    DDRE |= _BV(PE3);                                 /* ENA: D5, OC3A */
    DDRH |= _BV(PH3);                                 /* ENB: D6, OC4A */
    TCCR3A = _BV(COM3A1) | _BV(WGM30);                /* fast PWM, 8 bit, 62.5 kHz */
    TCCR3B = _BV(WGM32) | _BV(CS30);
    TCCR4A = _BV(COM4A1) | _BV(WGM40);
    TCCR4B = _BV(WGM42) | _BV(CS40);
    OCR1A = TICKS - 1; /* TOP first: the timer starts with its clock (simavr reads TOP then) */
    TCCR1B = _BV(WGM12) | _BV(CS10); /* CTC: the 1 kHz control tick */
    adc_start(1); /* the ACS712 on A1 */
    EICRB = _BV(ISC40) | _BV(ISC50); /* D2/D3 (INT4/INT5): any edge */
    EIMSK = _BV(INT4) | _BV(INT5);
    rig_serve(&motor);
}
