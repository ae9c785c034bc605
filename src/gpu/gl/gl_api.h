/* The OpenGL API as every GL file in lmgi sees it: include this, never <GL/gl.h> directly.
 *
 * OSMesa and EGL each have their own GL entry points, so no GL function is linked by symbol. This header
 * declares only the GL types, enums and PFN typedefs (<GL/glcorearb.h> without GL_GLEXT_PROTOTYPES, so
 * calling a function missing from the list below does not compile), a table of function pointers that
 * gl_context.c fills from the backend it chose, and a macro per function that calls through the table of
 * the context current on the calling thread: `glClear(m)` reads `(lm_gl_cur->glClear)(m)`.
 *
 * To call a GL function that is not listed yet, add it to LM_GL_FUNCTIONS and give it a #define below;
 * a _Static_assert catches a listed function without its #define. */
#ifndef LM_GL_API_H
#define LM_GL_API_H

#ifdef GL_GLEXT_PROTOTYPES
#error "gl_api.h: GL_GLEXT_PROTOTYPES would declare GL functions that clash with the dispatch macros"
#endif
#include <GL/glcorearb.h>

#include "../../core/error.h"
#include "gl_context.h"

/* X(name, PFN type) for every GL function lmgi calls (src/ and tests/), then a few more core <= 4.5
 * functions kept ready; every one must exist in a 4.5 core context, or the context is refused. */
#define LM_GL_FUNCTIONS(X) \
    X(glActiveTexture, PFNGLACTIVETEXTUREPROC) \
    X(glAttachShader, PFNGLATTACHSHADERPROC) \
    X(glBeginQuery, PFNGLBEGINQUERYPROC) \
    X(glBindBuffer, PFNGLBINDBUFFERPROC) \
    X(glBindBufferBase, PFNGLBINDBUFFERBASEPROC) \
    X(glBindFramebuffer, PFNGLBINDFRAMEBUFFERPROC) \
    X(glBindImageTexture, PFNGLBINDIMAGETEXTUREPROC) \
    X(glBindRenderbuffer, PFNGLBINDRENDERBUFFERPROC) \
    X(glBindTexture, PFNGLBINDTEXTUREPROC) \
    X(glBindVertexArray, PFNGLBINDVERTEXARRAYPROC) \
    X(glBlendFunc, PFNGLBLENDFUNCPROC) \
    X(glBufferData, PFNGLBUFFERDATAPROC) \
    X(glBufferSubData, PFNGLBUFFERSUBDATAPROC) \
    X(glCheckFramebufferStatus, PFNGLCHECKFRAMEBUFFERSTATUSPROC) \
    X(glClear, PFNGLCLEARPROC) \
    X(glClearBufferData, PFNGLCLEARBUFFERDATAPROC) \
    X(glClearBufferfv, PFNGLCLEARBUFFERFVPROC) \
    X(glClearBufferiv, PFNGLCLEARBUFFERIVPROC) \
    X(glClearColor, PFNGLCLEARCOLORPROC) \
    X(glClearDepth, PFNGLCLEARDEPTHPROC) \
    X(glClearTexImage, PFNGLCLEARTEXIMAGEPROC) \
    X(glClearTexSubImage, PFNGLCLEARTEXSUBIMAGEPROC) \
    X(glClipControl, PFNGLCLIPCONTROLPROC) \
    X(glColorMask, PFNGLCOLORMASKPROC) \
    X(glColorMaski, PFNGLCOLORMASKIPROC) \
    X(glCompileShader, PFNGLCOMPILESHADERPROC) \
    X(glCopyImageSubData, PFNGLCOPYIMAGESUBDATAPROC) \
    X(glCreateProgram, PFNGLCREATEPROGRAMPROC) \
    X(glCreateShader, PFNGLCREATESHADERPROC) \
    X(glDeleteBuffers, PFNGLDELETEBUFFERSPROC) \
    X(glDeleteFramebuffers, PFNGLDELETEFRAMEBUFFERSPROC) \
    X(glDeleteProgram, PFNGLDELETEPROGRAMPROC) \
    X(glDeleteQueries, PFNGLDELETEQUERIESPROC) \
    X(glDeleteRenderbuffers, PFNGLDELETERENDERBUFFERSPROC) \
    X(glDeleteShader, PFNGLDELETESHADERPROC) \
    X(glDeleteTextures, PFNGLDELETETEXTURESPROC) \
    X(glDeleteVertexArrays, PFNGLDELETEVERTEXARRAYSPROC) \
    X(glDepthFunc, PFNGLDEPTHFUNCPROC) \
    X(glDepthMask, PFNGLDEPTHMASKPROC) \
    X(glDisable, PFNGLDISABLEPROC) \
    X(glDispatchCompute, PFNGLDISPATCHCOMPUTEPROC) \
    X(glDrawArrays, PFNGLDRAWARRAYSPROC) \
    X(glEnable, PFNGLENABLEPROC) \
    X(glEnableVertexAttribArray, PFNGLENABLEVERTEXATTRIBARRAYPROC) \
    X(glEndQuery, PFNGLENDQUERYPROC) \
    X(glFinish, PFNGLFINISHPROC) \
    X(glFramebufferRenderbuffer, PFNGLFRAMEBUFFERRENDERBUFFERPROC) \
    X(glFramebufferTexture2D, PFNGLFRAMEBUFFERTEXTURE2DPROC) \
    X(glGenBuffers, PFNGLGENBUFFERSPROC) \
    X(glGenerateMipmap, PFNGLGENERATEMIPMAPPROC) \
    X(glGenFramebuffers, PFNGLGENFRAMEBUFFERSPROC) \
    X(glGenQueries, PFNGLGENQUERIESPROC) \
    X(glGenRenderbuffers, PFNGLGENRENDERBUFFERSPROC) \
    X(glGenTextures, PFNGLGENTEXTURESPROC) \
    X(glGenVertexArrays, PFNGLGENVERTEXARRAYSPROC) \
    X(glGetError, PFNGLGETERRORPROC) \
    X(glGetIntegerv, PFNGLGETINTEGERVPROC) \
    X(glGetProgramInfoLog, PFNGLGETPROGRAMINFOLOGPROC) \
    X(glGetProgramiv, PFNGLGETPROGRAMIVPROC) \
    X(glGetQueryObjectui64v, PFNGLGETQUERYOBJECTUI64VPROC) \
    X(glGetShaderInfoLog, PFNGLGETSHADERINFOLOGPROC) \
    X(glGetShaderiv, PFNGLGETSHADERIVPROC) \
    X(glGetString, PFNGLGETSTRINGPROC) \
    X(glGetStringi, PFNGLGETSTRINGIPROC) \
    X(glGetTexImage, PFNGLGETTEXIMAGEPROC) \
    X(glGetTextureSubImage, PFNGLGETTEXTURESUBIMAGEPROC) \
    X(glGetUniformLocation, PFNGLGETUNIFORMLOCATIONPROC) \
    X(glLinkProgram, PFNGLLINKPROGRAMPROC) \
    X(glMemoryBarrier, PFNGLMEMORYBARRIERPROC) \
    X(glPixelStorei, PFNGLPIXELSTOREIPROC) \
    X(glReadPixels, PFNGLREADPIXELSPROC) \
    X(glRenderbufferStorage, PFNGLRENDERBUFFERSTORAGEPROC) \
    X(glScissor, PFNGLSCISSORPROC) \
    X(glShaderSource, PFNGLSHADERSOURCEPROC) \
    X(glStencilFunc, PFNGLSTENCILFUNCPROC) \
    X(glStencilMask, PFNGLSTENCILMASKPROC) \
    X(glStencilOp, PFNGLSTENCILOPPROC) \
    X(glTexImage2D, PFNGLTEXIMAGE2DPROC) \
    X(glTexParameterf, PFNGLTEXPARAMETERFPROC) \
    X(glTexParameteri, PFNGLTEXPARAMETERIPROC) \
    X(glTexStorage2D, PFNGLTEXSTORAGE2DPROC) \
    X(glTexSubImage2D, PFNGLTEXSUBIMAGE2DPROC) \
    X(glUniform1f, PFNGLUNIFORM1FPROC) \
    X(glUniform1i, PFNGLUNIFORM1IPROC) \
    X(glUniform2i, PFNGLUNIFORM2IPROC) \
    X(glUniform3f, PFNGLUNIFORM3FPROC) \
    X(glUniform3fv, PFNGLUNIFORM3FVPROC) \
    X(glUniformMatrix4fv, PFNGLUNIFORMMATRIX4FVPROC) \
    X(glUseProgram, PFNGLUSEPROGRAMPROC) \
    X(glVertexAttribPointer, PFNGLVERTEXATTRIBPOINTERPROC) \
    X(glViewport, PFNGLVIEWPORTPROC) \
    /* not called yet, kept ready: */ \
    X(glBindBufferRange, PFNGLBINDBUFFERRANGEPROC) \
    X(glBlendEquation, PFNGLBLENDEQUATIONPROC) \
    X(glBlendFuncSeparate, PFNGLBLENDFUNCSEPARATEPROC) \
    X(glBlitFramebuffer, PFNGLBLITFRAMEBUFFERPROC) \
    X(glClientWaitSync, PFNGLCLIENTWAITSYNCPROC) \
    X(glCullFace, PFNGLCULLFACEPROC) \
    X(glDeleteSync, PFNGLDELETESYNCPROC) \
    X(glDepthRange, PFNGLDEPTHRANGEPROC) \
    X(glDisableVertexAttribArray, PFNGLDISABLEVERTEXATTRIBARRAYPROC) \
    X(glDrawArraysInstanced, PFNGLDRAWARRAYSINSTANCEDPROC) \
    X(glDrawBuffer, PFNGLDRAWBUFFERPROC) \
    X(glDrawBuffers, PFNGLDRAWBUFFERSPROC) \
    X(glDrawElements, PFNGLDRAWELEMENTSPROC) \
    X(glDrawElementsInstanced, PFNGLDRAWELEMENTSINSTANCEDPROC) \
    X(glFenceSync, PFNGLFENCESYNCPROC) \
    X(glFlush, PFNGLFLUSHPROC) \
    X(glFramebufferTexture, PFNGLFRAMEBUFFERTEXTUREPROC) \
    X(glFramebufferTextureLayer, PFNGLFRAMEBUFFERTEXTURELAYERPROC) \
    X(glFrontFace, PFNGLFRONTFACEPROC) \
    X(glGetBufferSubData, PFNGLGETBUFFERSUBDATAPROC) \
    X(glGetFloatv, PFNGLGETFLOATVPROC) \
    X(glGetIntegeri_v, PFNGLGETINTEGERI_VPROC) \
    X(glGetTexLevelParameteriv, PFNGLGETTEXLEVELPARAMETERIVPROC) \
    X(glIsEnabled, PFNGLISENABLEDPROC) \
    X(glMapBufferRange, PFNGLMAPBUFFERRANGEPROC) \
    X(glPolygonOffset, PFNGLPOLYGONOFFSETPROC) \
    X(glQueryCounter, PFNGLQUERYCOUNTERPROC) \
    X(glReadBuffer, PFNGLREADBUFFERPROC) \
    X(glTexImage3D, PFNGLTEXIMAGE3DPROC) \
    X(glTexParameterfv, PFNGLTEXPARAMETERFVPROC) \
    X(glTexStorage2DMultisample, PFNGLTEXSTORAGE2DMULTISAMPLEPROC) \
    X(glTexStorage3D, PFNGLTEXSTORAGE3DPROC) \
    X(glTexSubImage3D, PFNGLTEXSUBIMAGE3DPROC) \
    X(glUniform1fv, PFNGLUNIFORM1FVPROC) \
    X(glUniform1iv, PFNGLUNIFORM1IVPROC) \
    X(glUniform1ui, PFNGLUNIFORM1UIPROC) \
    X(glUniform2f, PFNGLUNIFORM2FPROC) \
    X(glUniform2fv, PFNGLUNIFORM2FVPROC) \
    X(glUniform4f, PFNGLUNIFORM4FPROC) \
    X(glUniform4fv, PFNGLUNIFORM4FVPROC) \
    X(glUniformMatrix3fv, PFNGLUNIFORMMATRIX3FVPROC) \
    X(glUnmapBuffer, PFNGLUNMAPBUFFERPROC) \
    X(glVertexAttribIPointer, PFNGLVERTEXATTRIBIPOINTERPROC) \

typedef struct lm_gl_fns {
#define LM_GL_FNS_MEMBER(name, type) type name;
    LM_GL_FUNCTIONS(LM_GL_FNS_MEMBER)
#undef LM_GL_FNS_MEMBER
} lm_gl_fns;

/* The table of the context current on this thread (lm_gl_context_create / lm_gl_make_current set it);
 * NULL when none is. */
extern _Thread_local const lm_gl_fns *lm_gl_cur;

/* Fills every entry from get_proc; the first one missing is an error naming it and `backend`. */
lm_status lm_gl_fns_load(lm_gl_fns *fns, lm_gl_proc (*get_proc)(const char *name), const char *backend,
                         lm_error *err);

#ifndef LM_GL_API_NO_DISPATCH_MACROS
#define glActiveTexture (lm_gl_cur->glActiveTexture)
#define glAttachShader (lm_gl_cur->glAttachShader)
#define glBeginQuery (lm_gl_cur->glBeginQuery)
#define glBindBuffer (lm_gl_cur->glBindBuffer)
#define glBindBufferBase (lm_gl_cur->glBindBufferBase)
#define glBindBufferRange (lm_gl_cur->glBindBufferRange)
#define glBindFramebuffer (lm_gl_cur->glBindFramebuffer)
#define glBindImageTexture (lm_gl_cur->glBindImageTexture)
#define glBindRenderbuffer (lm_gl_cur->glBindRenderbuffer)
#define glBindTexture (lm_gl_cur->glBindTexture)
#define glBindVertexArray (lm_gl_cur->glBindVertexArray)
#define glBlendEquation (lm_gl_cur->glBlendEquation)
#define glBlendFunc (lm_gl_cur->glBlendFunc)
#define glBlendFuncSeparate (lm_gl_cur->glBlendFuncSeparate)
#define glBlitFramebuffer (lm_gl_cur->glBlitFramebuffer)
#define glBufferData (lm_gl_cur->glBufferData)
#define glBufferSubData (lm_gl_cur->glBufferSubData)
#define glClearBufferData (lm_gl_cur->glClearBufferData)
#define glCheckFramebufferStatus (lm_gl_cur->glCheckFramebufferStatus)
#define glClear (lm_gl_cur->glClear)
#define glClearBufferfv (lm_gl_cur->glClearBufferfv)
#define glClearBufferiv (lm_gl_cur->glClearBufferiv)
#define glClearColor (lm_gl_cur->glClearColor)
#define glClearDepth (lm_gl_cur->glClearDepth)
#define glClearTexImage (lm_gl_cur->glClearTexImage)
#define glClearTexSubImage (lm_gl_cur->glClearTexSubImage)
#define glClientWaitSync (lm_gl_cur->glClientWaitSync)
#define glClipControl (lm_gl_cur->glClipControl)
#define glColorMask (lm_gl_cur->glColorMask)
#define glColorMaski (lm_gl_cur->glColorMaski)
#define glCompileShader (lm_gl_cur->glCompileShader)
#define glCopyImageSubData (lm_gl_cur->glCopyImageSubData)
#define glCreateProgram (lm_gl_cur->glCreateProgram)
#define glCreateShader (lm_gl_cur->glCreateShader)
#define glCullFace (lm_gl_cur->glCullFace)
#define glDeleteBuffers (lm_gl_cur->glDeleteBuffers)
#define glDeleteFramebuffers (lm_gl_cur->glDeleteFramebuffers)
#define glDeleteProgram (lm_gl_cur->glDeleteProgram)
#define glDeleteQueries (lm_gl_cur->glDeleteQueries)
#define glDeleteRenderbuffers (lm_gl_cur->glDeleteRenderbuffers)
#define glDeleteShader (lm_gl_cur->glDeleteShader)
#define glDeleteSync (lm_gl_cur->glDeleteSync)
#define glDeleteTextures (lm_gl_cur->glDeleteTextures)
#define glDeleteVertexArrays (lm_gl_cur->glDeleteVertexArrays)
#define glDepthFunc (lm_gl_cur->glDepthFunc)
#define glDepthMask (lm_gl_cur->glDepthMask)
#define glDepthRange (lm_gl_cur->glDepthRange)
#define glDisable (lm_gl_cur->glDisable)
#define glDisableVertexAttribArray (lm_gl_cur->glDisableVertexAttribArray)
#define glDispatchCompute (lm_gl_cur->glDispatchCompute)
#define glDrawArrays (lm_gl_cur->glDrawArrays)
#define glDrawArraysInstanced (lm_gl_cur->glDrawArraysInstanced)
#define glDrawBuffer (lm_gl_cur->glDrawBuffer)
#define glDrawBuffers (lm_gl_cur->glDrawBuffers)
#define glDrawElements (lm_gl_cur->glDrawElements)
#define glDrawElementsInstanced (lm_gl_cur->glDrawElementsInstanced)
#define glEnable (lm_gl_cur->glEnable)
#define glEnableVertexAttribArray (lm_gl_cur->glEnableVertexAttribArray)
#define glEndQuery (lm_gl_cur->glEndQuery)
#define glFenceSync (lm_gl_cur->glFenceSync)
#define glFinish (lm_gl_cur->glFinish)
#define glFlush (lm_gl_cur->glFlush)
#define glFramebufferRenderbuffer (lm_gl_cur->glFramebufferRenderbuffer)
#define glFramebufferTexture (lm_gl_cur->glFramebufferTexture)
#define glFramebufferTexture2D (lm_gl_cur->glFramebufferTexture2D)
#define glFramebufferTextureLayer (lm_gl_cur->glFramebufferTextureLayer)
#define glFrontFace (lm_gl_cur->glFrontFace)
#define glGenBuffers (lm_gl_cur->glGenBuffers)
#define glGenFramebuffers (lm_gl_cur->glGenFramebuffers)
#define glGenQueries (lm_gl_cur->glGenQueries)
#define glGenRenderbuffers (lm_gl_cur->glGenRenderbuffers)
#define glGenTextures (lm_gl_cur->glGenTextures)
#define glGenVertexArrays (lm_gl_cur->glGenVertexArrays)
#define glGenerateMipmap (lm_gl_cur->glGenerateMipmap)
#define glGetBufferSubData (lm_gl_cur->glGetBufferSubData)
#define glGetError (lm_gl_cur->glGetError)
#define glGetFloatv (lm_gl_cur->glGetFloatv)
#define glGetIntegeri_v (lm_gl_cur->glGetIntegeri_v)
#define glGetIntegerv (lm_gl_cur->glGetIntegerv)
#define glGetProgramInfoLog (lm_gl_cur->glGetProgramInfoLog)
#define glGetProgramiv (lm_gl_cur->glGetProgramiv)
#define glGetQueryObjectui64v (lm_gl_cur->glGetQueryObjectui64v)
#define glGetShaderInfoLog (lm_gl_cur->glGetShaderInfoLog)
#define glGetShaderiv (lm_gl_cur->glGetShaderiv)
#define glGetString (lm_gl_cur->glGetString)
#define glGetStringi (lm_gl_cur->glGetStringi)
#define glGetTexImage (lm_gl_cur->glGetTexImage)
#define glGetTextureSubImage (lm_gl_cur->glGetTextureSubImage)
#define glGetTexLevelParameteriv (lm_gl_cur->glGetTexLevelParameteriv)
#define glGetUniformLocation (lm_gl_cur->glGetUniformLocation)
#define glIsEnabled (lm_gl_cur->glIsEnabled)
#define glLinkProgram (lm_gl_cur->glLinkProgram)
#define glMapBufferRange (lm_gl_cur->glMapBufferRange)
#define glMemoryBarrier (lm_gl_cur->glMemoryBarrier)
#define glPixelStorei (lm_gl_cur->glPixelStorei)
#define glPolygonOffset (lm_gl_cur->glPolygonOffset)
#define glQueryCounter (lm_gl_cur->glQueryCounter)
#define glReadBuffer (lm_gl_cur->glReadBuffer)
#define glReadPixels (lm_gl_cur->glReadPixels)
#define glRenderbufferStorage (lm_gl_cur->glRenderbufferStorage)
#define glScissor (lm_gl_cur->glScissor)
#define glShaderSource (lm_gl_cur->glShaderSource)
#define glStencilFunc (lm_gl_cur->glStencilFunc)
#define glStencilMask (lm_gl_cur->glStencilMask)
#define glStencilOp (lm_gl_cur->glStencilOp)
#define glTexImage2D (lm_gl_cur->glTexImage2D)
#define glTexImage3D (lm_gl_cur->glTexImage3D)
#define glTexParameterf (lm_gl_cur->glTexParameterf)
#define glTexParameterfv (lm_gl_cur->glTexParameterfv)
#define glTexParameteri (lm_gl_cur->glTexParameteri)
#define glTexStorage2D (lm_gl_cur->glTexStorage2D)
#define glTexStorage3D (lm_gl_cur->glTexStorage3D)
#define glTexStorage2DMultisample (lm_gl_cur->glTexStorage2DMultisample)
#define glTexSubImage2D (lm_gl_cur->glTexSubImage2D)
#define glTexSubImage3D (lm_gl_cur->glTexSubImage3D)
#define glUniform1f (lm_gl_cur->glUniform1f)
#define glUniform1fv (lm_gl_cur->glUniform1fv)
#define glUniform1i (lm_gl_cur->glUniform1i)
#define glUniform1iv (lm_gl_cur->glUniform1iv)
#define glUniform1ui (lm_gl_cur->glUniform1ui)
#define glUniform2f (lm_gl_cur->glUniform2f)
#define glUniform2fv (lm_gl_cur->glUniform2fv)
#define glUniform2i (lm_gl_cur->glUniform2i)
#define glUniform3f (lm_gl_cur->glUniform3f)
#define glUniform3fv (lm_gl_cur->glUniform3fv)
#define glUniform4f (lm_gl_cur->glUniform4f)
#define glUniform4fv (lm_gl_cur->glUniform4fv)
#define glUniformMatrix3fv (lm_gl_cur->glUniformMatrix3fv)
#define glUniformMatrix4fv (lm_gl_cur->glUniformMatrix4fv)
#define glUnmapBuffer (lm_gl_cur->glUnmapBuffer)
#define glUseProgram (lm_gl_cur->glUseProgram)
#define glVertexAttribIPointer (lm_gl_cur->glVertexAttribIPointer)
#define glVertexAttribPointer (lm_gl_cur->glVertexAttribPointer)
#define glViewport (lm_gl_cur->glViewport)

/* Every listed function has its #define (the stringified expansion must be "(lm_gl_cur->name)"). */
#define LM_GL_STR_(x) #x
#define LM_GL_XSTR_(x) LM_GL_STR_(x)
#define LM_GL_CHECK_DEFINE(name, type) \
    _Static_assert(sizeof(LM_GL_XSTR_(name)) == sizeof("(lm_gl_cur->" #name ")"), \
                   "gl_api.h: " #name " is listed in LM_GL_FUNCTIONS but has no #define");
LM_GL_FUNCTIONS(LM_GL_CHECK_DEFINE)
#undef LM_GL_CHECK_DEFINE
#endif

#endif
