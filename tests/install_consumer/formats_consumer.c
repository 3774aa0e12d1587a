/* formats_consumer.c - the formats library alone, linked fully static
 * (-static) with `pkg-config --static --libs vdsh-formats`
 * (tests/test_install.sh): writes a file through vdsh_output.h (its
 * pthread mutex) and prints the library version. */
#include <stdio.h>
#include <vdsh/vdsh_output.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: formats_consumer OUT\n");
        return 2;
    }
    vdsh_error err;
    if (vdsh_output_write(argv[1], "vdsh\n", 5, &err) != VDSH_OK) {
        fprintf(stderr, "formats_consumer: %s\n", err.msg);
        return 1;
    }
    printf("formats %s: wrote %s\n", vdsh_library_version(), argv[1]);
    return 0;
}
