// The n a module serves: within N_RANGE, or the exported n where it is baked in.
function checkedN(value) {
  const fits = N_RANGE === null ? value === EXPORTED_N : value >= N_RANGE[0] && value <= N_RANGE[1];
  if (typeof value !== "number" || !fits) {
    const valid = N_RANGE === null ? `${EXPORTED_N} (its constants are fitted for it)` : `in [${N_RANGE[0]}, ${N_RANGE[1]}]`;
    throw new RangeError(`specula ${LOBE}: n = ${value} is not served by this export; n must be ${valid}`);
  }
  return value;
}
