#version 450
layout(location = 0) in vec2 barycentrics;
layout(location = 1) flat in uint triangle;
layout(location = 0) out uint outTriangle;
layout(location = 1) out vec2 outBarycentrics;

void main() {
  outTriangle = triangle;
  outBarycentrics = barycentrics;
}
