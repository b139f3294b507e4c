#version 330 core
// Lines and triangles: world-coordinate vertices (metres) with per-vertex RGBA8 colour.
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 color;

uniform mat4 view_projection;  // world -> clip, column-major

out vec4 v_color;

void main() {
  gl_Position = view_projection * vec4(position, 1.0);
  v_color = color;
}
