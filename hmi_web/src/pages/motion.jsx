// Motion: a faceplate for every PLCopen axis (MC_AXIS instance) of the
// running program, polled from GET /api/v1/axes.
import { useEffect, useState } from 'preact/hooks';
import { getAxes } from '../api/endpoints.js';
import { AXES_POLL_MS, normalizeAxes } from '../lib/axis_faceplate.js';
import { usePoll } from '../lib/poll.js';
import { AxisFaceplate } from '../components/axis_faceplate.jsx';
import { ErrorNote } from '../components/common.jsx';

const nowMs = () => (typeof performance !== 'undefined' ? performance.now() : Date.now());

export function MotionPage({ session }) {
  const { data, error, loading } = usePoll(async () => normalizeAxes(await getAxes(), nowMs()), AXES_POLL_MS);
  const [notice, setNotice] = useState(null);
  // Ages grow between answers: redraw so a PLC that stops answering greys the faceplates.
  const [, setTick] = useState(0);
  useEffect(() => {
    const t = setInterval(() => setTick((n) => n + 1), AXES_POLL_MS);
    return () => clearInterval(t);
  }, []);
  const axes = data || [];
  return (
    <>
      <h1>Motion</h1>
      <p class="hint">Every PLCopen axis (MC_AXIS) of the running program. Disable takes an axis to Disabled at its next scan whatever its MC_Power asks; Enable permits its MC_Power again. Reset (engineers) acknowledges an axis error as MC_Reset does.</p>
      <ErrorNote error={error} />
      {notice ? <p class="ok-note" role="status">{notice}</p> : null}
      {!loading && !error && axes.length === 0 ? <p class="hint">This program has no MC_AXIS.</p> : null}
      <div class="grid">
        {axes.map((a) => <AxisFaceplate key={a.name} axis={a} session={session} nowMs={nowMs()} onNotice={setNotice} />)}
      </div>
    </>
  );
}
