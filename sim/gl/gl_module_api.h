/* C interface of an off-screen GL backend module (libpvb_gl_<name>.so).
 *
 * The simulator dlopen()s exactly one module per process, so a process never
 * loads both libEGL and libOSMesa (MuJoCo 2.2.2 picks its GL loader from the
 * libraries already loaded and fails when it finds both).  Each module links
 * only its own GL library. */
#ifndef PVB_GL_MODULE_API_H
#define PVB_GL_MODULE_API_H

#ifdef __cplusplus
extern "C" {
#endif

/* Creates an off-screen context able to render width x height pixels and makes
 * it current on the calling thread.  Returns NULL on failure and writes a
 * one-line reason into err (at most err_len bytes, NUL-terminated). */
void* pvb_gl_create(int width, int height, char* err, int err_len);
/* Makes the context current on the calling thread; returns 0 on success. */
int pvb_gl_make_current(void* ctx);
/* Releases the context. */
void pvb_gl_destroy(void* ctx);
/* Human-readable description: API, platform, GL vendor and renderer. */
const char* pvb_gl_describe(void* ctx);

#ifdef __cplusplus
}
#endif
#endif
