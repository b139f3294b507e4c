#version 330 core
in vec4 v_color;
out vec4 frag_color;

void main() {
  // Round points: gl_PointCoord spans [0, 1]^2 over the square sprite; keep the inscribed disc.
  vec2 from_center = gl_PointCoord - vec2(0.5);
  if (dot(from_center, from_center) > 0.25) discard;
  frag_color = v_color;
}
