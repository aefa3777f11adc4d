// The owners of EGL handles on headless EGL (Mesa's surfaceless platform, llvmpipe here): an EGL
// surface is destroyed once, by its last owner, and a move hands it on without destroying it; a
// surface destroyed while current leaves the thread's context current without it; a context
// deletes the programs kept in it when it goes, whether or not it is current then, and gives
// the thread back the context it had.
// Example failures: a moved-from surface destroying the surface its new owner draws into; a
// surface left alive (deferred by EGL) after its GBM surface or X window was destroyed; kept
// programs that outlive their context in a share group because it was not current when it went
// (the leak the output teardown had); another context left current, or none, after a context
// was destroyed beside it.

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "render/egl.h"
#include "render/gl.h"

namespace basalt::render {
namespace {

constexpr const char* kVertex = R"(#version 300 es
void main() { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }
)";
constexpr const char* kFragment = R"(#version 300 es
precision mediump float;
out vec4 colour;
void main() { colour = vec4(1.0); }
)";

class EglOwners : public ::testing::Test {
 protected:
  void SetUp() override {
    auto display = EglDisplay::openSurfaceless();
    if (!display) GTEST_SKIP() << "no headless EGL here: " << display.error().describe();
    display_ = std::move(*display);
    if (!display_->hasExtension("EGL_KHR_surfaceless_context")) {
      GTEST_SKIP() << "this EGL has no surfaceless contexts (EGL_KHR_surfaceless_context)";
    }
    const EGLint attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display_->handle(), attributes, &config_, 1, &count) || count == 0) {
      GTEST_SKIP() << "this EGL offers no OpenGL ES 3 pbuffer configuration";
    }
  }
  void TearDown() override {
    if (display_) eglMakeCurrent(display_->handle(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }

  [[nodiscard]] EGLSurface pbuffer() const {
    const EGLint attributes[] = {EGL_WIDTH, 8, EGL_HEIGHT, 8, EGL_NONE};
    return eglCreatePbufferSurface(display_->handle(), config_, attributes);
  }
  /// Whether `surface` is still a surface of the display (EGL answers EGL_BAD_SURFACE once it
  /// is destroyed).
  [[nodiscard]] bool alive(EGLSurface surface) const {
    EGLint width = 0;
    const bool ok = eglQuerySurface(display_->handle(), surface, EGL_WIDTH, &width) == EGL_TRUE;
    if (!ok) {
      EXPECT_EQ(eglGetError(), EGL_BAD_SURFACE);
    }
    return ok && width == 8;
  }
  [[nodiscard]] std::unique_ptr<EglContext> context(const EglContext* shareWith = nullptr) const {
    auto c = EglContext::create(display_, config_, shareWith);
    EXPECT_TRUE(c) << (c ? "" : c.error().describe());
    return c ? std::move(*c) : nullptr;
  }

  std::shared_ptr<EglDisplay> display_;
  EGLConfig config_ = nullptr;
};

TEST_F(EglOwners, ASurfaceIsDestroyedOnceByItsLastOwner) {
  const EGLSurface handle = pbuffer();
  ASSERT_NE(handle, EGL_NO_SURFACE);
  {
    EglSurface first = EglSurface::wrap(display_, handle);
    ASSERT_TRUE(first);
    EglSurface second(std::move(first));
    EXPECT_FALSE(first);  // NOLINT(bugprone-use-after-move): what a move leaves
    EXPECT_EQ(second.handle(), handle);
    first.reset();  // an empty owner destroys nothing
    EXPECT_TRUE(alive(handle)) << "a moved-from surface destroyed the surface";
    EglSurface third;
    third = std::move(second);
    {
      EglSurface gone(std::move(second));  // NOLINT(bugprone-use-after-move): moving an empty one
    }
    EXPECT_TRUE(alive(handle)) << "a moved-from surface destroyed the surface";
    EXPECT_EQ(third.handle(), handle);
  }
  EXPECT_FALSE(alive(handle)) << "the last owner did not destroy the surface";
}

TEST_F(EglOwners, MovingOntoASurfaceDestroysTheOneItHeld) {
  const EGLSurface kept = pbuffer();
  const EGLSurface replaced = pbuffer();
  ASSERT_NE(kept, EGL_NO_SURFACE);
  ASSERT_NE(replaced, EGL_NO_SURFACE);
  EglSurface owner = EglSurface::wrap(display_, replaced);
  owner = EglSurface::wrap(display_, kept);
  EXPECT_FALSE(alive(replaced)) << "the surface the owner held before leaked";
  EXPECT_TRUE(alive(kept));
}

TEST_F(EglOwners, AReleasedSurfaceIsTheCallersToDestroy) {
  const EGLSurface handle = pbuffer();
  ASSERT_NE(handle, EGL_NO_SURFACE);
  {
    EglSurface owner = EglSurface::wrap(display_, handle);
    EXPECT_EQ(owner.release(), handle);
    EXPECT_FALSE(owner);
    EXPECT_EQ(owner.display(), nullptr) << "the display is let go with the surface";
  }
  EXPECT_TRUE(alive(handle)) << "a released surface was destroyed";
  EXPECT_TRUE(eglDestroySurface(display_->handle(), handle));
}

TEST_F(EglOwners, ACurrentSurfaceGoesAndItsContextStaysCurrent) {
  auto ctx = context();
  ASSERT_NE(ctx, nullptr);
  EglSurface surface = EglSurface::wrap(display_, pbuffer());
  ASSERT_TRUE(surface);
  const EGLSurface handle = surface.handle();
  ASSERT_TRUE(ctx->makeCurrent(handle));
  ASSERT_EQ(eglGetCurrentSurface(EGL_DRAW), handle);
  surface.reset();
  EXPECT_EQ(eglGetCurrentSurface(EGL_DRAW), EGL_NO_SURFACE) << "the surface is let go, not kept until later";
  EXPECT_EQ(eglGetCurrentSurface(EGL_READ), EGL_NO_SURFACE);
  EXPECT_EQ(eglGetCurrentContext(), ctx->handle()) << "the context stays current without a surface";
  EXPECT_EQ(EglContext::current(), ctx.get());
  EXPECT_FALSE(alive(handle));
}

TEST_F(EglOwners, AWindowSurfaceOnNoWindowFailsWithAMessage) {
  // The surfaceless platform has no windows: the error names what the surface was for.
  auto surface = EglSurface::createWindow(display_, config_, nullptr, "the test's window");
  ASSERT_FALSE(surface);
  EXPECT_NE(surface.error().describe().find("the test's window"), std::string::npos) << surface.error().describe();
}

/// A program kept in `context` (current) under `key`; its name.
GLuint keepOne(EglContext& context, const std::string& key) {
  auto program = gl::buildProgram(kVertex, kFragment, key);
  EXPECT_TRUE(program) << (program ? "" : program.error().describe());
  if (!program) return 0;
  return context.keepProgram(key, std::move(*program));
}

TEST_F(EglOwners, ReplacingAKeptProgramDeletesTheOldOne) {
  auto ctx = context();
  ASSERT_NE(ctx, nullptr);
  ASSERT_TRUE(ctx->makeCurrent());
  const GLuint first = keepOne(*ctx, "test.program");
  ASSERT_NE(first, 0u);
  EXPECT_EQ(ctx->keptProgram("test.program"), first);
  EXPECT_EQ(ctx->keptProgram("test.other"), 0u);
  const GLuint second = keepOne(*ctx, "test.program");
  EXPECT_EQ(ctx->keptProgram("test.program"), second);
  EXPECT_EQ(glIsProgram(first), GL_FALSE) << "the program replaced leaked";
  EXPECT_EQ(glIsProgram(second), GL_TRUE);
  EXPECT_EQ(gl::drainErrors(), static_cast<GLenum>(GL_NO_ERROR));
}

// The kept programs are looked for from a second context sharing the first one's objects: they
// stay there after the first context goes unless the first deleted them.
TEST_F(EglOwners, AContextDeletesItsKeptProgramsWhileAnotherIsCurrent) {
  auto owner = context();
  ASSERT_NE(owner, nullptr);
  auto witness = context(owner.get());
  ASSERT_NE(witness, nullptr);
  ASSERT_TRUE(owner->makeCurrent());
  const GLuint a = keepOne(*owner, "test.a");
  const GLuint b = keepOne(*owner, "test.b");
  ASSERT_NE(a, 0u);
  ASSERT_NE(b, 0u);
  ASSERT_TRUE(witness->makeCurrent());
  ASSERT_EQ(glIsProgram(a), GL_TRUE) << "the contexts do not share their programs";
  owner.reset();  // not current: the witness is
  EXPECT_EQ(eglGetCurrentContext(), witness->handle()) << "the thread's context was not given back";
  EXPECT_EQ(EglContext::current(), witness.get());
  EXPECT_EQ(glIsProgram(a), GL_FALSE) << "a kept program outlived its context";
  EXPECT_EQ(glIsProgram(b), GL_FALSE) << "a kept program outlived its context";
  EXPECT_EQ(gl::drainErrors(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(EglOwners, AContextDeletesItsKeptProgramsWhenNoneIsCurrent) {
  auto owner = context();
  ASSERT_NE(owner, nullptr);
  auto witness = context(owner.get());
  ASSERT_NE(witness, nullptr);
  ASSERT_TRUE(owner->makeCurrent());
  const GLuint kept = keepOne(*owner, "test.kept");
  ASSERT_NE(kept, 0u);
  ASSERT_TRUE(eglMakeCurrent(display_->handle(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT));
  owner.reset();
  EXPECT_EQ(eglGetCurrentContext(), EGL_NO_CONTEXT) << "the deletion left a context current";
  ASSERT_TRUE(witness->makeCurrent());
  EXPECT_EQ(glIsProgram(kept), GL_FALSE) << "a kept program outlived its context";
  EXPECT_EQ(gl::drainErrors(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(EglOwners, AContextDeletesItsKeptProgramsWhileCurrent) {
  auto owner = context();
  ASSERT_NE(owner, nullptr);
  auto witness = context(owner.get());
  ASSERT_NE(witness, nullptr);
  ASSERT_TRUE(owner->makeCurrent());
  const GLuint kept = keepOne(*owner, "test.kept");
  ASSERT_NE(kept, 0u);
  owner.reset();
  EXPECT_EQ(eglGetCurrentContext(), EGL_NO_CONTEXT);
  EXPECT_EQ(EglContext::current(), nullptr);
  ASSERT_TRUE(witness->makeCurrent());
  EXPECT_EQ(glIsProgram(kept), GL_FALSE) << "a kept program outlived its context";
}

}  // namespace
}  // namespace basalt::render
