// Formation edges: their colour on the strain scale, and quads a few pixels wide to draw them.
import * as THREE from 'three';

// Strain (|d| - d_t) / d_t: closer than d_t, at d_t, farther.
export const STRAIN_COLOURS = { closer: '#7b3294', atSet: '#404040', farther: '#e66101' };

const [CLOSER, AT_SET, FARTHER] = [STRAIN_COLOURS.closer, STRAIN_COLOURS.atSet, STRAIN_COLOURS.farther].map((c) => new THREE.Color(c));

// The colour of a strain on the symmetric scale [-scale, scale], written into `out`: from the colour
// at d_t towards closer or farther, mixed in linear light.
export function strainColour(strain, scale, out = new THREE.Color()) {
  const s = Math.max(-1, Math.min(1, strain / scale));
  return out.copy(AT_SET).lerp(s < 0 ? CLOSER : FARTHER, Math.abs(s));
}

// Edges as quads a few pixels wide whatever the zoom (WebGL draws lines 1 px wide): each edge is an
// instance of a unit quad whose ends are moved to the edge's ends on screen and widened there.
const EDGE_VERTEX = `
uniform vec2 resolution;
uniform float width;
attribute vec3 instanceStart;
attribute vec3 instanceEnd;
attribute vec3 instanceColour;
varying vec3 vColour;
void main() {
  vColour = instanceColour;
  vec4 a = projectionMatrix * modelViewMatrix * vec4(instanceStart, 1.0);
  vec4 b = projectionMatrix * modelViewMatrix * vec4(instanceEnd, 1.0);
  vec2 along = normalize((b.xy / b.w - a.xy / a.w) * resolution);
  vec4 end = position.x < 0.5 ? a : b;
  end.xy += vec2(-along.y, along.x) * position.y * width / resolution * end.w;
  gl_Position = end;
}`;
const EDGE_FRAGMENT = `
uniform float opacity;
varying vec3 vColour;
void main() {
  gl_FragColor = vec4(vColour, opacity);
  #include <colorspace_fragment>
}`;

export function edgeQuads(count, opacity) {
  const geometry = new THREE.InstancedBufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute([0, -1, 0, 1, -1, 0, 0, 1, 0, 1, 1, 0], 3));
  geometry.setIndex([0, 1, 2, 2, 1, 3]);
  for (const name of ['instanceStart', 'instanceEnd', 'instanceColour']) {
    geometry.setAttribute(name, new THREE.InstancedBufferAttribute(new Float32Array(3 * Math.max(count, 1)), 3));
  }
  geometry.instanceCount = 0;
  const material = new THREE.ShaderMaterial({
    vertexShader: EDGE_VERTEX, fragmentShader: EDGE_FRAGMENT, transparent: opacity < 1, depthWrite: opacity === 1,
    uniforms: { resolution: { value: new THREE.Vector2(1, 1) }, width: { value: 2.5 }, opacity: { value: opacity } },
  });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.frustumCulled = false;
  return mesh;
}
