/* context_consumer.c - built against an installed vdsh with vdsh::context
 * (tests/test_install.sh), through find_package and through
 * `pkg-config vdsh-context`: links the context library (and with it, for
 * static libraries, GLFW and EGL) and resolves its symbols. No context is
 * made: the test machine may have no EGL device. */
#include <stdio.h>
#include <vr_context.h>

int main(void)
{
    printf("context: %s\n", (void *)vr_context_create != NULL ? "linked" : "missing");
    return 0;
}
