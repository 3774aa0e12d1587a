/*
 * vr_context.h - GL contexts for the runtime (prefix vr_context_): a
 * headless one through EGL, or a window through GLFW using its EGL context
 * API. The runtime itself (vr.h) never creates a context; the viewer and
 * the tests use this file to get one, and then both kinds render through
 * the same offscreen framebuffer (vr_draw), the window only adding a blit.
 *
 * Headless: the EGL device platform (EGL_EXT_platform_device) on the first
 * device that initialises, hardware devices before Mesa's software one;
 * else Mesa's surfaceless platform (EGL_MESA_platform_surfaceless). The
 * context is desktop GL 3.3 core or later, made current without a surface
 * (EGL_KHR_surfaceless_context), or with a 1x1 pbuffer where that
 * extension is missing.
 *
 * Window: GLFW with GLFW_CONTEXT_CREATION_API = GLFW_EGL_CONTEXT_API, GL
 * 3.3 core. GLFW state is process-wide: one window context at a time.
 *
 * Does not: draw, load scenes, or handle input (the caller polls GLFW
 * with the window from vr_context_window).
 *
 * Errors: VR_ERR_MISSING when no EGL display or window system is there
 * (tests turn that into "skipped"), VR_ERR_GL when one is there but the
 * context cannot be made; the message says which platform failed and why.
 *
 * Ownership: vr_context_create returns a context owned by the caller,
 * current on the calling thread; vr_context_destroy (NULL is fine)
 * releases and destroys it. Destroy every runtime object first.
 * Threading: one thread per context.
 */
#ifndef VR_CONTEXT_H
#define VR_CONTEXT_H

#include "vr.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vr_context vr_context;

typedef enum vr_context_kind { VR_CONTEXT_HEADLESS = 0, VR_CONTEXT_WINDOW = 1 } vr_context_kind;

typedef enum vr_egl_platform {
    VR_EGL_AUTO = 0, /* device, then surfaceless */
    VR_EGL_DEVICE = 1,
    VR_EGL_SURFACELESS = 2
} vr_egl_platform;

typedef struct vr_context_desc {
    vr_context_kind kind;         /* 0: headless */
    vr_egl_platform egl_platform; /* headless only; 0: auto */
    int width, height;            /* window size; 0: VR_DEFAULT_WIDTH x _HEIGHT */
    const char *title;            /* window title; NULL: "vdsh-view" */
    int vsync;                    /* window: 1 waits for vertical sync */
} vr_context_desc;

vr_result vr_context_create(const vr_context_desc *desc, vr_context **out, vr_error *err);

void vr_context_destroy(vr_context *c);

/* "EGL device platform (EGL_MESA_device_software)", "EGL surfaceless
 * platform", "GLFW window, EGL context"; never NULL. */
const char *vr_context_description(const vr_context *c);

/* The GLFWwindow of a window context (NULL when headless). */
void *vr_context_window(vr_context *c);

/* Show the default framebuffer (window contexts; no-op when headless). */
void vr_context_swap(vr_context *c);

#ifdef __cplusplus
}
#endif

#endif /* VR_CONTEXT_H */
