#version 330 core
// Points in world coordinates (metres), per-point RGBA8 colour, size in pixels.
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 color;

uniform mat4 view_projection;  // world -> clip, column-major
uniform float point_size_px;
uniform float opacity;  // multiplies the per-point alpha

out vec4 v_color;

void main() {
  gl_Position = view_projection * vec4(position, 1.0);
  gl_PointSize = point_size_px;  // honoured because the renderer enables GL_PROGRAM_POINT_SIZE
  v_color = vec4(color.rgb, color.a * opacity);
}
