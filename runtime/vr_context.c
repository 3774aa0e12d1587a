/*
 * vr_context.c - headless EGL and GLFW window contexts (vr_context.h).
 */
#if defined(__SANITIZE_ADDRESS__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* dl_iterate_phdr */
#endif
#include "vr_context.h"
#include "vr_internal.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#ifdef VR_HAVE_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SANITIZE_ADDRESS__
#include <dlfcn.h>
#include <link.h>

static int pin_library(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    (void)data;
    if (info->dlpi_name && info->dlpi_name[0]) {
        void *h = dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        if (h)
            dlclose(h); /* drops this reference; RTLD_NODELETE stays */
    }
    return 0;
}

/* AddressSanitizer builds only: keep every library loaded so far (the GL
 * driver and its LLVM among them) loaded until exit. eglTerminate unloads
 * Mesa's driver, whose globals still point at a few allocations it never
 * frees; once unloaded, LeakSanitizer reports those as leaks in
 * "<unknown module>" frames that no suppression can name. Kept loaded,
 * they are reachable, as they would be without the unload. */
static void pin_libraries(void)
{
    dl_iterate_phdr(pin_library, NULL);
}
#else
static void pin_libraries(void)
{
}
#endif

struct vr_context {
    EGLDisplay display;
    EGLContext context;
    EGLSurface surface; /* pbuffer, only without surfaceless support */
    void *window;       /* GLFWwindow */
    char description[160];
};

static int has_ext(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: return "EGL error";
    }
}

/* A GL 3.3 core context on an initialised display, made current. */
static vr_result egl_make_context(vr_context *c, const char *what, vr_error *err)
{
    const char *ext = eglQueryString(c->display, EGL_EXTENSIONS);
    if (!eglBindAPI(EGL_OPENGL_API))
        return vr_fail(err, VR_ERR_GL, "%s: desktop OpenGL not supported (%s)", what,
                       egl_error_name(eglGetError()));
    EGLConfig config = (EGLConfig)0;
    int surfaceless = has_ext(ext, "EGL_KHR_surfaceless_context");
    if (!surfaceless || !has_ext(ext, "EGL_KHR_no_config_context")) {
        const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                               EGL_PBUFFER_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(c->display, want, &config, 1, &n) || n < 1)
            return vr_fail(err, VR_ERR_GL, "%s: no EGL config for desktop OpenGL", what);
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                              3,
                              EGL_CONTEXT_MINOR_VERSION,
                              3,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_NONE};
    c->context = eglCreateContext(c->display, config, EGL_NO_CONTEXT, attribs);
    if (c->context == EGL_NO_CONTEXT)
        return vr_fail(err, VR_ERR_GL, "%s: cannot create a GL 3.3 core context (%s)", what,
                       egl_error_name(eglGetError()));
    if (!surfaceless) {
        const EGLint pb[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        c->surface = eglCreatePbufferSurface(c->display, config, pb);
        if (c->surface == EGL_NO_SURFACE)
            return vr_fail(err, VR_ERR_GL, "%s: cannot create a pbuffer (%s)", what,
                           egl_error_name(eglGetError()));
    }
    EGLSurface s = surfaceless ? EGL_NO_SURFACE : c->surface;
    if (!eglMakeCurrent(c->display, s, s, c->context))
        return vr_fail(err, VR_ERR_GL, "%s: eglMakeCurrent failed (%s)", what,
                       egl_error_name(eglGetError()));
    return VR_OK;
}

static void egl_release(vr_context *c)
{
    if (c->display == EGL_NO_DISPLAY)
        return;
    eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (c->surface != EGL_NO_SURFACE)
        eglDestroySurface(c->display, c->surface);
    if (c->context != EGL_NO_CONTEXT)
        eglDestroyContext(c->display, c->context);
    eglTerminate(c->display);
    c->display = EGL_NO_DISPLAY;
    c->context = EGL_NO_CONTEXT;
    c->surface = EGL_NO_SURFACE;
}

/* Try the device platform: hardware devices first, then software. */
static vr_result try_device(vr_context *c, vr_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_ext(client, "EGL_EXT_platform_device") ||
        !has_ext(client, "EGL_EXT_device_enumeration"))
        return vr_fail(err, VR_ERR_MISSING, "EGL device platform: not supported by this EGL");
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC device_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!query_devices || !get_display)
        return vr_fail(err, VR_ERR_MISSING, "EGL device platform: entry points missing");
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (!query_devices(16, devices, &n) || n < 1)
        return vr_fail(err, VR_ERR_MISSING, "EGL device platform: no devices");
    vr_result r = VR_ERR_MISSING;
    for (int pass = 0; pass < 2; pass++) {
        for (EGLint i = 0; i < n; i++) {
            const char *dext = device_string ? device_string(devices[i], EGL_EXTENSIONS) : "";
            int software = has_ext(dext, "EGL_MESA_device_software");
            if (software != pass)
                continue;
            c->display = get_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
            EGLint major = 0, minor = 0;
            if (c->display == EGL_NO_DISPLAY || !eglInitialize(c->display, &major, &minor)) {
                r = vr_fail(err, VR_ERR_MISSING, "EGL device %d: cannot initialise (%s)", (int)i,
                            egl_error_name(eglGetError()));
                c->display = EGL_NO_DISPLAY;
                continue;
            }
            r = egl_make_context(c, "EGL device platform", err);
            if (r == VR_OK) {
                snprintf(c->description, sizeof c->description,
                         "EGL %d.%d device platform, device %d%s", (int)major, (int)minor, (int)i,
                         software ? " (EGL_MESA_device_software)" : "");
                return VR_OK;
            }
            egl_release(c);
        }
    }
    return r;
}

static vr_result try_surfaceless(vr_context *c, vr_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_ext(client, "EGL_MESA_platform_surfaceless"))
        return vr_fail(err, VR_ERR_MISSING, "EGL surfaceless platform: not supported");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display)
        return vr_fail(err, VR_ERR_MISSING, "EGL surfaceless platform: entry point missing");
    c->display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    EGLint major = 0, minor = 0;
    if (c->display == EGL_NO_DISPLAY || !eglInitialize(c->display, &major, &minor)) {
        c->display = EGL_NO_DISPLAY;
        return vr_fail(err, VR_ERR_MISSING, "EGL surfaceless platform: cannot initialise (%s)",
                       egl_error_name(eglGetError()));
    }
    vr_result r = egl_make_context(c, "EGL surfaceless platform", err);
    if (r != VR_OK) {
        egl_release(c);
        return r;
    }
    snprintf(c->description, sizeof c->description, "EGL %d.%d surfaceless platform", (int)major,
             (int)minor);
    return VR_OK;
}

static vr_result create_headless(vr_context *c, vr_egl_platform platform, vr_error *err)
{
    vr_error first;
    vr_result r = VR_ERR_MISSING;
    if (platform != VR_EGL_SURFACELESS) {
        r = try_device(c, &first);
        if (r == VR_OK || platform == VR_EGL_DEVICE)
            return r == VR_OK ? r : vr_fail(err, r, "%s", first.msg);
    }
    vr_error second;
    r = try_surfaceless(c, &second);
    if (r == VR_OK)
        return r;
    if (platform == VR_EGL_SURFACELESS)
        return vr_fail(err, r, "%s", second.msg);
    return vr_fail(err, r, "no headless GL context: %s; %s", first.msg, second.msg);
}

#ifdef VR_HAVE_GLFW
static vr_result create_window(vr_context *c, const vr_context_desc *d, vr_error *err)
{
    const char *msg = NULL;
    if (!glfwInit()) {
        glfwGetError(&msg);
        return vr_fail(err, VR_ERR_MISSING, "cannot open a window: %s",
                       msg ? msg : "GLFW initialisation failed");
    }
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    /* The scene has its own depth buffer in the offscreen framebuffer. */
    glfwWindowHint(GLFW_DEPTH_BITS, 0);
    GLFWwindow *w = glfwCreateWindow(d->width, d->height, d->title, NULL, NULL);
    if (!w) {
        glfwGetError(&msg);
        glfwTerminate();
        return vr_fail(err, VR_ERR_MISSING, "cannot open a window: %s",
                       msg ? msg : "glfwCreateWindow failed");
    }
    glfwMakeContextCurrent(w);
    glfwSwapInterval(d->vsync ? 1 : 0);
    c->window = w;
    int major = 0, minor = 0, rev = 0;
    glfwGetVersion(&major, &minor, &rev);
    snprintf(c->description, sizeof c->description, "GLFW %d.%d.%d window, EGL context", major,
             minor, rev);
    return VR_OK;
}
#endif

vr_result vr_context_create(const vr_context_desc *desc, vr_context **out, vr_error *err)
{
    vr_context_desc d = desc ? *desc : (vr_context_desc){0};
    if (!d.width && !d.height) {
        d.width = VR_DEFAULT_WIDTH;
        d.height = VR_DEFAULT_HEIGHT;
    }
    if (!d.title)
        d.title = "vdsh-view";
    if (!out || (unsigned)d.kind > VR_CONTEXT_WINDOW ||
        (unsigned)d.egl_platform > VR_EGL_SURFACELESS || d.width < 1 || d.height < 1)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_context_create: bad descriptor");
    vr_context *c = calloc(1, sizeof *c);
    if (!c)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "context: out of memory");
    c->display = EGL_NO_DISPLAY;
    c->context = EGL_NO_CONTEXT;
    c->surface = EGL_NO_SURFACE;
    vr_result r;
    if (d.kind == VR_CONTEXT_WINDOW) {
#ifdef VR_HAVE_GLFW
        r = create_window(c, &d, err);
#else
        r = vr_fail(err, VR_ERR_MISSING, "cannot open a window: built without GLFW");
#endif
    } else {
        r = create_headless(c, d.egl_platform, err);
    }
    if (r == VR_OK && !glGetString(GL_VERSION))
        r = vr_fail(err, VR_ERR_GL, "%s: the context is current but GL does not answer",
                    c->description);
    if (r != VR_OK) {
        vr_context_destroy(c);
        return r;
    }
    pin_libraries();
    *out = c;
    return VR_OK;
}

void vr_context_destroy(vr_context *c)
{
    if (!c)
        return;
#ifdef VR_HAVE_GLFW
    if (c->window) {
        glfwMakeContextCurrent(NULL);
        glfwDestroyWindow(c->window);
        glfwTerminate();
    }
#endif
    egl_release(c);
    free(c);
}

const char *vr_context_description(const vr_context *c)
{
    return c ? c->description : "(no context)";
}

void *vr_context_window(vr_context *c)
{
    return c ? c->window : NULL;
}

void vr_context_swap(vr_context *c)
{
#ifdef VR_HAVE_GLFW
    if (c && c->window)
        glfwSwapBuffers(c->window);
#else
    (void)c;
#endif
}
