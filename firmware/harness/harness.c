/* Runs a rig's firmware ELF on a simulated ATmega2560 at 16 MHz (simavr), UART0 behind a
 * pseudo-terminal; prints "uart0 at <device path>" and runs until killed. */
#include <stdio.h>

#include "sim_avr.h"
#include "sim_elf.h"
#include "uart_pty.h"

int main(int argc, char **argv) {
    elf_firmware_t firmware = {{0}};
    if (argc != 2 || elf_read_firmware(argv[1], &firmware) != 0) {
        fprintf(stderr, "usage: harness FIRMWARE.elf (a readable ATmega2560 ELF)\n");
        return 2;
    }
    avr_t *avr = avr_make_mcu_by_name("atmega2560");
    if (avr == NULL) return 2;
    avr_init(avr);
    avr->frequency = 16000000;
    avr_load_firmware(avr, &firmware);
    static uart_pty_t pty;
    uart_pty_init(avr, &pty);
    uart_pty_connect(&pty, '0');
    printf("uart0 at %s\n", pty.pty.slavename);
    fflush(stdout);
    for (;;) {
        int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) return state == cpu_Done ? 0 : 1;
    }
}
