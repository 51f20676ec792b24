/* Mesa 25.0.7, zink over lavapipe: a glTexSubImage2D from client memory reaches draws issued
 * before it. GL orders commands (GL 4.6 core, 2.3.1); a draw samples the texture as it was when
 * the draw was issued.
 *
 * A texture (256x256 RGBA8) is bound once. Step k uploads it filled with k, then draws one pixel
 * (k, 0) that records the texel it samples, after a longer draw that samples it too. Every fourth
 * step starts with glFinish (in radiosity: the read-back after each shot). Steps 0 to 2 record
 * step 3's value: the upload of step 3 was written into the texture while the draws of steps
 * 0 to 2 were still queued. Right with llvmpipe (25.0.7), with zink on Mesa 22.3.6, with
 * GALLIUM_THREAD=0, and with the same upload from a pixel unpack buffer (REPRO_PBO=1).
 *
 * Reading of Mesa's source: u_threaded_context's tc_texture_subdata writes an upload larger
 * than TC_MAX_SUBDATA_BYTES directly from the calling thread, PIPE_MAP_UNSYNCHRONIZED, when
 * tc_resource_batch_usage_test_busy finds the texture idle and zink's is_resource_busy agrees.
 * The texture's batch usage is recorded when it is bound as a sampler view, not by each draw
 * that samples it, and zink has not yet received the queued draws: both call it idle.
 *
 *   cc -O2 -o tc-upload-race tc-upload-race.c -lEGL -lOpenGL
 *   MESA_LOADER_DRIVER_OVERRIDE=zink LIBGL_ALWAYS_SOFTWARE=1 ./tc-upload-race
 * prints the steps that sampled another step's upload; exit status 1 if any did. */
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { SIDE = 256, STEPS = 64, WORK = 512 };

static GLuint shader(GLenum kind, const char *src)
{
   GLuint s = glCreateShader(kind);
   glShaderSource(s, 1, &src, NULL);
   glCompileShader(s);
   GLint ok;
   glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
   if (!ok) { char log[2000]; glGetShaderInfoLog(s, sizeof log, NULL, log); fprintf(stderr, "%s\n", log); exit(2); }
   return s;
}

int main(void)
{
   PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
      (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
   EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
   if (!eglInitialize(dpy, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API)) { fprintf(stderr, "no EGL\n"); return 2; }
   const EGLint attrs[] = { EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE };
   EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attrs);
   if (!ctx || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) { fprintf(stderr, "no context\n"); return 2; }
   printf("%s | %s\n", glGetString(GL_RENDERER), glGetString(GL_VERSION));

   /* The texture the draws sample, bound once; the target they draw into. */
   GLuint tex, rb, fbo, vao, vbo, pbo = 0;
   glGenTextures(1, &tex);
   glBindTexture(GL_TEXTURE_2D, tex);
   glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
   glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
   glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, SIDE, SIDE, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
   glGenRenderbuffers(1, &rb);
   glBindRenderbuffer(GL_RENDERBUFFER, rb);
   glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, WORK, WORK);
   glGenFramebuffers(1, &fbo);
   glBindFramebuffer(GL_FRAMEBUFFER, fbo);
   glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
   glViewport(0, 0, WORK, WORK);
   glClearColor(-1, -1, -1, -1);
   glClear(GL_COLOR_BUFFER_BIT);
   glEnable(GL_SCISSOR_TEST);

   GLuint prog = glCreateProgram();
   glAttachShader(prog, shader(GL_VERTEX_SHADER,
      "#version 130\nin vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }\n"));
   glAttachShader(prog, shader(GL_FRAGMENT_SHADER,
      "#version 130\nuniform sampler2D t; uniform int loops; out vec4 c;\n"
      "void main() {\n"
      "  float s = texelFetch(t, ivec2(gl_FragCoord.xy) % 256, 0).r, a = s;\n"
      "  for (int i = 0; i < loops; ++i) a = fract(a * 1.618 + 0.1);\n"
      "  c = vec4(s, a, 0.0, 1.0);\n"
      "}\n"));
   glBindAttribLocation(prog, 0, "p");
   glBindFragDataLocation(prog, 0, "c");
   glLinkProgram(prog);
   glUseProgram(prog);
   glUniform1i(glGetUniformLocation(prog, "t"), 0);
   GLint loops = glGetUniformLocation(prog, "loops");
   const float big[] = { -1, -1, 3, -1, -1, 3 };
   glGenVertexArrays(1, &vao);
   glBindVertexArray(vao);
   glGenBuffers(1, &vbo);
   glBindBuffer(GL_ARRAY_BUFFER, vbo);
   glBufferData(GL_ARRAY_BUFFER, sizeof big, big, GL_STATIC_DRAW);
   glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, 0);
   glEnableVertexAttribArray(0);

   int use_pbo = getenv("REPRO_PBO") != NULL;
   if (use_pbo)
      glGenBuffers(1, &pbo);
   static unsigned char texels[SIDE * SIDE * 4];
   for (int k = 0; k < STEPS; ++k) {
      if (k % 4 == 0)
         glFinish();   /* every fourth step, as after a read-back: the driver idle */
      memset(texels, k, sizeof texels);
      if (use_pbo) {
         glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
         glBufferData(GL_PIXEL_UNPACK_BUFFER, sizeof texels, texels, GL_STREAM_DRAW);
         glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, SIDE, SIDE, GL_RGBA, GL_UNSIGNED_BYTE, 0);
         glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
      } else {
         glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, SIDE, SIDE, GL_RGBA, GL_UNSIGNED_BYTE, texels);
      }
      glScissor(0, 1, WORK, WORK - 1);   /* the long pass */
      glUniform1i(loops, 200);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glScissor(k, 0, 1, 1);             /* the record of what step k sampled */
      glUniform1i(loops, 0);
      glDrawArrays(GL_TRIANGLES, 0, 3);
   }
   float seen[STEPS * 4];
   glReadPixels(0, 0, STEPS, 1, GL_RGBA, GL_FLOAT, seen);
   int wrong = 0;
   for (int k = 0; k < STEPS; ++k) {
      int got = (int)(seen[4 * k] * 255.0f + 0.5f);
      if (got != k && wrong++ < 8)
         printf("step %d sampled step %d's upload\n", k, got);
   }
   printf("%d of %d steps sampled another step's upload (%s)\n", wrong, STEPS,
          use_pbo ? "from a buffer object" : "from client memory");
   return wrong != 0;
}
