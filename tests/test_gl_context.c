/* gpu/gl/gl_context: the GL backend chosen at run time by LMGI_GL. osmesa gives OSMesa with GL >= 4.5; egl
 * gives an EGL context whose render and readback match OSMesa's numbers (skipped where no EGL vendor is
 * installed); a bad value is an error naming LMGI_GL; auto keeps EGL only for a hardware renderer; two
 * contexts of different backends take turns on one thread. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "../src/gpu/gl/gl_api.h"

#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/gpu/gl/gl_context.h"
#include "../src/gpu/gl/gl_shader.h"
#include "../src/gpu/gl/offscreen.h"

#define W 32
#define H 24

/* Where glvnd looks for EGL vendors; with none there EGL cannot work and the EGL tests skip. */
static int egl_vendor_installed(void)
{
    glob_t g;
    int found = glob("/usr/share/glvnd/egl_vendor.d/*.json", 0, NULL, &g) == 0 && g.gl_pathc > 0;
    if (!found)
        found = glob("/etc/glvnd/egl_vendor.d/*.json", 0, NULL, &g) == 0 && g.gl_pathc > 0;
    globfree(&g);
    return found;
}

static int has_gpu_device(void)
{
    glob_t g;
    int found = glob("/dev/dri/renderD*", 0, NULL, &g) == 0 && g.gl_pathc > 0;
    globfree(&g);
    return found || access("/dev/nvidia0", F_OK) == 0;
}

static lm_gl_context *create_with(const char *choice)
{
    if (choice)
        setenv("LMGI_GL", choice, 1);
    else
        unsetenv("LMGI_GL");
    lm_gl_context *gl = NULL;
    lm_error err;
    if (lm_gl_context_create(&gl, &err) != LM_OK) {
        if (choice && !strcmp(choice, "osmesa") && strstr(err.msg, "OSMesa is not available")) {
            print_message("skipped: %s\n", err.msg); /* a machine with a GPU need not have Mesa */
            skip();
        }
        fail_msg("LMGI_GL=%s: %s", choice ? choice : "(unset)", err.msg);
    }
    print_message("LMGI_GL=%s: %s\n", choice ? choice : "(unset)", lm_gl_context_description(gl));
    return gl;
}

/* A triangle over part of a W x H float target, its colour a mix of transcendental functions of the
 * pixel position, read back as RGB. */
static void render(float *rgb)
{
    static const char *vs =
        "#version 450 core\n"
        "void main() {\n"
        "    const vec2 p[3] = vec2[3](vec2(-0.9, -0.8), vec2(0.7, -0.3), vec2(-0.2, 0.9));\n"
        "    gl_Position = vec4(p[gl_VertexID], 0.0, 1.0);\n"
        "}\n";
    static const char *fs =
        "#version 450 core\n"
        "out vec4 color;\n"
        "void main() {\n"
        "    vec2 f = gl_FragCoord.xy;\n"
        "    color = vec4(sin(0.37 * f.x) + f.y / 7.0, exp(-f.x / 13.0) * cos(f.y),\n"
        "                 sqrt(f.x * f.y) / 3.0, 1.0);\n"
        "}\n";
    lm_error err;
    unsigned prog = 0, vao = 0;
    if (lm_gl_program("test triangle", vs, fs, &prog, &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_offscreen o;
    if (lm_offscreen_begin_float(&o, W, H, &err) != LM_OK)
        fail_msg("%s", err.msg);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glUseProgram(prog);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    lm_offscreen_read_rgb(&o, rgb);
    if (lm_gl_check("test triangle", &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_offscreen_release(&o);
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &vao);
    glUseProgram(0);
    glDeleteProgram(prog);
}

/* The picture is not trivial: some pixels covered, some not. */
static void check_picture(const float *rgb)
{
    int covered = 0;
    for (int i = 0; i < W * H; i++)
        covered += rgb[3 * i] != 0.0f || rgb[3 * i + 1] != 0.0f || rgb[3 * i + 2] != 0.0f;
    assert_true(covered > W * H / 8);
    assert_true(covered < W * H);
}

static void test_osmesa(void **state)
{
    (void)state;
    lm_gl_context *gl = create_with("osmesa");
    assert_int_equal(lm_gl_context_backend(gl), LM_GL_BACKEND_OSMESA);
    assert_non_null(strstr(lm_gl_context_description(gl), "(OSMesa; LMGI_GL=osmesa)"));
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    assert_true(major * 10 + minor >= 45);
    assert_non_null(lm_gl_get_proc("glClipControl"));
    lm_gl_context_destroy(gl);
    assert_null(lm_gl_get_proc("glClipControl")); /* nothing current any more */
    unsetenv("LMGI_GL");
}

/* A shader that does not compile, and a program that does not link, fail with the shader's name, the
 * stage and the driver's log. */
static void test_shader_errors_name_the_shader(void **state)
{
    (void)state;
    lm_gl_context *gl = create_with("osmesa");
    static const char *VS = "#version 450 core\nvoid main() { gl_Position = vec4(0.0); }\n";
    static const char *BAD_FS = "#version 450 core\nout vec4 c;\nvoid main() { c = undefined_thing; }\n";
    static const char *UNLINKABLE_FS = "#version 450 core\nin vec3 never_written;\nout vec4 c;\n"
                                       "void main() { c = vec4(never_written, 1.0); }\n";
    unsigned prog = 0;
    lm_error err;
    assert_int_equal(lm_gl_program("my_broken_shader", VS, BAD_FS, &prog, &err), LM_ERR_BACKEND);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "my_broken_shader"));
    assert_non_null(strstr(err.msg, "fragment"));
    assert_non_null(strstr(err.msg, "undefined_thing")); /* the driver's log names the culprit */
    assert_int_equal(lm_gl_program("my_unlinkable_program", VS, UNLINKABLE_FS, &prog, &err), LM_ERR_BACKEND);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "my_unlinkable_program"));
    assert_non_null(strstr(err.msg, "link"));
    assert_int_equal(lm_gl_compute_program("my_compute", "#version 450 core\nlayout(local_size_x = 1) in;\n"
                                           "void main() { nope(); }\n", &prog, &err), LM_ERR_BACKEND);
    assert_non_null(strstr(err.msg, "my_compute"));
    lm_gl_context_destroy(gl);
    unsetenv("LMGI_GL");
}

static void test_egl_matches_osmesa(void **state)
{
    (void)state;
    if (!egl_vendor_installed()) {
        print_message("skipped: no EGL vendor in /usr/share/glvnd/egl_vendor.d (install libegl-mesa0)\n");
        skip();
    }
    static float a[W * H * 3], b[W * H * 3];
    lm_gl_context *gl = create_with("osmesa");
    render(a);
    lm_gl_context_destroy(gl);

    gl = create_with("egl");
    assert_int_equal(lm_gl_context_backend(gl), LM_GL_BACKEND_EGL);
    assert_non_null(strstr(lm_gl_context_description(gl), "(EGL, "));
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    assert_true(major * 10 + minor >= 45);
    render(b);
    lm_gl_context_destroy(gl);
    unsetenv("LMGI_GL");

    check_picture(a);
    double worst = 0.0;
    for (int i = 0; i < W * H * 3; i++)
        worst = fmax(worst, fabs((double)a[i] - (double)b[i]));
    print_message("largest difference EGL vs OSMesa: %g\n", worst);
    /* Both are llvmpipe here, so the numbers are the same; a GPU may round differently. */
    assert_true(worst < 1e-4);
}

static void test_bad_value(void **state)
{
    (void)state;
    setenv("LMGI_GL", "bogus", 1);
    lm_gl_context *gl = NULL;
    lm_error err;
    assert_int_not_equal(lm_gl_context_create(&gl, &err), LM_OK);
    assert_null(gl);
    print_message("LMGI_GL=bogus: %s\n", err.msg);
    assert_non_null(strstr(err.msg, "LMGI_GL"));
    assert_non_null(strstr(err.msg, "bogus"));
    assert_non_null(strstr(err.msg, "osmesa"));
    unsetenv("LMGI_GL");
}

static void test_auto(void **state)
{
    (void)state;
    lm_gl_context *gl = create_with(NULL);
    char d[512];
    snprintf(d, sizeof d, "%s", lm_gl_context_description(gl));
    if (lm_gl_context_backend(gl) == LM_GL_BACKEND_EGL) {
        /* auto keeps EGL only for a hardware renderer */
        const char *r = (const char *)glGetString(GL_RENDERER);
        assert_null(strstr(r, "llvmpipe"));
        assert_null(strstr(r, "softpipe"));
    } else {
        assert_true(strstr(d, "(OSMesa; EGL gave ") || strstr(d, "(OSMesa; EGL failed: "));
        static float rgb[W * H * 3];
        render(rgb);
        check_picture(rgb);
    }
    if (!has_gpu_device())
        assert_int_equal(lm_gl_context_backend(gl), LM_GL_BACKEND_OSMESA);
    lm_gl_context_destroy(gl);

    /* "auto" said outright is the same as unset; the decision is remembered */
    gl = create_with("auto");
    assert_string_equal(lm_gl_context_description(gl), d);
    lm_gl_context_destroy(gl);
    unsetenv("LMGI_GL");
}

/* An OSMesa and an EGL context on one thread, made current in turns: each draws with its own table. */
static void test_switching(void **state)
{
    (void)state;
    if (!egl_vendor_installed()) {
        print_message("skipped: no EGL vendor in /usr/share/glvnd/egl_vendor.d\n");
        skip();
    }
    static float first[W * H * 3], again[W * H * 3];
    lm_gl_context *os = create_with("osmesa");
    lm_gl_context *egl = create_with("egl");
    unsetenv("LMGI_GL");
    lm_error err;
    render(first); /* egl is current: created last */
    for (int round = 0; round < 2; round++) {
        assert_int_equal(lm_gl_make_current(os, &err), LM_OK);
        render(again);
        assert_memory_equal(first, again, sizeof first);
        assert_int_equal(lm_gl_make_current(egl, &err), LM_OK);
        render(again);
        assert_memory_equal(first, again, sizeof first);
    }
    lm_gl_context_destroy(egl);
    assert_int_equal(lm_gl_make_current(os, &err), LM_OK);
    render(again);
    assert_memory_equal(first, again, sizeof first);
    lm_gl_context_destroy(os);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_osmesa),
        cmocka_unit_test(test_shader_errors_name_the_shader),
        cmocka_unit_test(test_egl_matches_osmesa),
        cmocka_unit_test(test_bad_value),
        cmocka_unit_test(test_auto),
        cmocka_unit_test(test_switching),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
