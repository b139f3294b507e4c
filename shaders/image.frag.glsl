#version 330 core
in vec2 v_uv;
out vec4 frag_color;

uniform sampler2D image;  // grey textures arrive as (g, g, g, 1) through the texture swizzle

void main() { frag_color = vec4(texture(image, v_uv).rgb, 1.0); }
