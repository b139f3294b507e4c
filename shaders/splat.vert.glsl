#version 330 core
// One triangle covering the whole viewport, from gl_VertexID alone (no vertex buffer):
// corners (-1, -1), (3, -1), (-1, 3) in normalized device coordinates.
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
