// A mission's route (tmem.figures.viewer.data.mission_route): each leg a line from where the group
// was when it began (when known) through its points, the points as small dots, the goal as a ring.
import * as THREE from 'three';
import { edgeQuads } from 'tmem/edges';

export const ROUTE_COLOURS = { route: '#2ca02c', goal: '#d62728' };

// Every point of the route's legs (none without a route).
export function routePoints(route) {
  return route ? route.legs.flatMap((leg) => leg.points) : [];
}

// The ends of the route's segments, two by two.
function segmentEnds(route) {
  const ends = [];
  for (const leg of route.legs) {
    const line = leg.from ? [leg.from, ...leg.points] : leg.points;
    for (let k = 1; k < line.length; k++) ends.push(line[k - 1], line[k]);
  }
  return ends;
}

// The route's lines (quads a few pixels wide, as the formation edges), its points and its goal:
// `at(values)` is the world point of a route point, `marks(count, size, ring, colour)` makes the
// scene's dots (a ring when `ring`).
export function routeObjects(route, at, marks) {
  const ends = segmentEnds(route).map(at);
  const lines = edgeQuads(ends.length / 2, 1);
  const { instanceStart, instanceEnd, instanceColour } = lines.geometry.attributes;
  const colour = new THREE.Color(ROUTE_COLOURS.route);
  for (let k = 0; k < ends.length / 2; k++) {
    instanceStart.setXYZ(k, ...ends[2 * k].toArray());
    instanceEnd.setXYZ(k, ...ends[2 * k + 1].toArray());
    instanceColour.setXYZ(k, colour.r, colour.g, colour.b);
  }
  lines.geometry.instanceCount = ends.length / 2;
  const stops = routePoints(route);
  const dots = marks(stops.length, 7, false, ROUTE_COLOURS.route);
  stops.forEach((p, k) => dots.geometry.attributes.position.setXYZ(k, ...at(p).toArray()));
  if (!route.goal) return [lines, dots];
  const goal = marks(1, 22, true, ROUTE_COLOURS.goal);
  goal.geometry.attributes.position.setXYZ(0, ...at(route.goal).toArray());
  goal.renderOrder = 2;
  return [lines, dots, goal];
}
