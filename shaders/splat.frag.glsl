#version 330 core
// Writes points splatted in software (point_splat.h) into the target: each covered pixel's
// colour and its depth, so that the depth test against what is already drawn (and what is
// drawn later) works as it does for GL_POINTS.
uniform sampler2D splat_color;   // RGBA8, rows bottom-up like the viewport
uniform usampler2D splat_depth;  // R32UI: 24-bit window depth, 0xFFFFFFFF where no point
uniform ivec2 viewport_origin;   // the viewport's lower-left corner in window pixels

out vec4 frag_color;

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy) - viewport_origin;
  uint depth = texelFetch(splat_depth, texel, 0).r;
  if (depth == 0xFFFFFFFFu) discard;
  frag_color = texelFetch(splat_color, texel, 0);
  gl_FragDepth = float(depth) / 16777215.0;
}
