#version 450
// Both eyes in one pass (multiview): each triangle's corners fetched by vertex index from the
// scene's own arrays, so that the fragment knows its triangle and barycentrics.
#extension GL_EXT_multiview : require

layout(std430, set = 0, binding = 0) readonly buffer Positions { float positions[]; };  // xyz per vertex
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };       // 3 per triangle
layout(push_constant) uniform Views { mat4 worldToClip[2]; } views;

layout(location = 0) out vec2 barycentrics;  // of corners 1 and 2, perspective-correct
layout(location = 1) flat out uint triangle;

void main() {
  const uint corner = uint(gl_VertexIndex) % 3u;
  const uint v = indices[gl_VertexIndex];
  const vec3 p = vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
  gl_Position = views.worldToClip[gl_ViewIndex] * vec4(p, 1.0);
  barycentrics = vec2(corner == 1u ? 1.0 : 0.0, corner == 2u ? 1.0 : 0.0);
  triangle = uint(gl_VertexIndex) / 3u;
}
