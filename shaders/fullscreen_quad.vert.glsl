// Full-screen quad for every fragment pass (docs/DESIGN.md section 9): four corners from
// gl_VertexID drawn as a triangle strip, no vertex buffers. Each fragment = one texel of the
// render target = one vector entry (or one partial sum of a reduction).
void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
