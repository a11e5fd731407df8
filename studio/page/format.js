// Camera settings as a camera shows them, and the nearest step of a table.
export function shutterText(s) { return s >= 0.3 ? `${s}s` : `1/${Math.round(1 / s)}`; }

export function nearestIndex(list, value) {
  let best = 0;
  list.forEach((v, i) => {
    if (Math.abs(Math.log(v / value)) < Math.abs(Math.log(list[best] / value))) best = i;
  });
  return best;
}
