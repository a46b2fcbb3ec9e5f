// The OpenGL 4.5 core entry points the renderer uses, loaded through the context's own GetProcAddress
// (OSMesaGetProcAddress or eglGetProcAddress), and the contexts that own them. Internal to src/render.
//
// Why a loader: libOSMesa exports every gl* symbol, and so does libGL. A process that has libGL loaded
// first (VTK links it) silently sends every direct gl* call to libGL, which has no current context.
// Loading each entry point from the context's library by name keeps the renderer correct whatever else is
// linked, and lets one renderer run on either context.
#pragma once

#include "temporal/core/error.h"
#include "temporal/render/render.h"

#include <GL/glcorearb.h>

#include <memory>
#include <string>

namespace temporal::render_detail {

// X(ReturnType-less PFN type, member name, GL name)
#define TEMPORAL_GL_FUNCTIONS(X)                                              \
  X(PFNGLGETSTRINGPROC, GetString)                                            \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                        \
  X(PFNGLGETERRORPROC, GetError)                                              \
  X(PFNGLENABLEPROC, Enable)                                                  \
  X(PFNGLDISABLEPROC, Disable)                                                \
  X(PFNGLVIEWPORTPROC, Viewport)                                              \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                    \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                                  \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                            \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                            \
  X(PFNGLBLENDFUNCPROC, BlendFunc)                                            \
  X(PFNGLPOLYGONOFFSETPROC, PolygonOffset)                                    \
  X(PFNGLCULLFACEPROC, CullFace)                                              \
  X(PFNGLFRONTFACEPROC, FrontFace)                                            \
  X(PFNGLFINISHPROC, Finish)                                                  \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                          \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                          \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                        \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                        \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                        \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                  \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                        \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                    \
  X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                                      \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                    \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                    \
  X(PFNGLGENERATEMIPMAPPROC, GenerateMipmap)                                  \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                          \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                      \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                  \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                          \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                          \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                    \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                          \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                  \
  X(PFNGLBUFFERDATAPROC, BufferData)                                          \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)              \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                        \
  X(PFNGLVERTEXATTRIB2FPROC, VertexAttrib2f)                                  \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)                                      \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                          \
  X(PFNGLCREATESHADERPROC, CreateShader)                                      \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                      \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                    \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                        \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                              \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                      \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                    \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                      \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                        \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                      \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                            \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                    \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                          \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                          \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                            \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                          \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                            \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                            \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                            \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                                            \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                          \
  X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv)                              \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                              \
  X(PFNGLGENQUERIESPROC, GenQueries)                                          \
  X(PFNGLDELETEQUERIESPROC, DeleteQueries)                                    \
  X(PFNGLBEGINQUERYPROC, BeginQuery)                                          \
  X(PFNGLENDQUERYPROC, EndQuery)                                              \
  X(PFNGLGETQUERYIVPROC, GetQueryiv)                                          \
  X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)

// The function table. Members are named without the `gl` prefix: gl.DrawElements(...).
struct GlFunctions {
#define TEMPORAL_GL_MEMBER(type, name) type name = nullptr;
  TEMPORAL_GL_FUNCTIONS(TEMPORAL_GL_MEMBER)
#undef TEMPORAL_GL_MEMBER
};

// An OpenGL 4.5 core context, current on the creating thread while it lives, and the entry points loaded from
// it. Two kinds make one (gl_context.cpp): OSMesa (llvmpipe in the process, the CI path) and EGL's device platform
// (any EGL device: Mesa's software device, or a GPU's driver through glvnd's libEGL; no window, no X, surfaceless).
// The renderer only sees this interface: every pass draws into its own FBOs and reads them back, so neither the
// default framebuffer (OSMesa's 1x1 buffer, none with EGL) nor the context's kind can change what it writes.
// LP_NUM_THREADS must be set before creation to take effect on llvmpipe.
class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  const GlFunctions& gl() const { return gl_; }
  // What made the context: kind "osmesa" or "egl", the EGL device index (-1 for OSMesa), and GL_VENDOR,
  // GL_RENDERER, GL_VERSION as the driver reports them.
  const GlInfo& info() const { return info_; }
  // "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6 (egl device 0)"
  std::string description() const;
  // Makes this context current on the calling thread again.
  virtual void make_current() = 0;

 protected:
  GlContext() = default;
  // Loads every entry point through `get_proc` ("glDrawElements" -> address) and fills info() from the then
  // current context. Internal error naming the entry points the driver lacks.
  Status load(void* (*get_proc)(const char*), const char* kind, int device);

 private:
  GlFunctions gl_;
  GlInfo info_;
};

// An OSMesa context (llvmpipe).
Expected<std::unique_ptr<GlContext>> create_osmesa_context();
// A context on EGL device `device` (index into eglQueryDevicesEXT's list); -1: the first hardware device, or
// the first device when every one is software.
Expected<std::unique_ptr<GlContext>> create_egl_context(int device);
// The context RenderOptions asks for (GlApi::Auto: a hardware EGL device when one exists, else OSMesa).
Expected<std::unique_ptr<GlContext>> create_context(GlApi api, int device);

// Compiles and links a program from vertex and fragment sources; the error carries the info log.
Expected<GLuint> build_program(const GlFunctions& gl, const std::string& name, const std::string& vertex,
                               const std::string& fragment);

// A pending GL error (glGetError) as an Internal error naming `where`; ok when none.
Status check_gl(const GlFunctions& gl, const char* where);

}  // namespace temporal::render_detail
