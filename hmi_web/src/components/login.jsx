// The login dialog: POST /api/v1/login, the token kept for this tab only.
import { useState } from 'preact/hooks';
import { login } from '../api/endpoints.js';
import { begin } from '../auth/session.js';
import { restart } from '../live/hub.js';
import { ErrorNote, Modal } from './common.jsx';

export function LoginDialog({ open, onClose }) {
  const [user, setUser] = useState('');
  const [password, setPassword] = useState('');
  const [error, setError] = useState(null);
  const [busy, setBusy] = useState(false);

  async function submit(e) {
    e.preventDefault();
    setBusy(true);
    setError(null);
    try {
      const answer = await login(user.trim(), password);
      begin(answer);
      restart();
      setPassword('');
      onClose();
    } catch (err) {
      setError(err.status === 401 ? 'The user name or the password is wrong.' : err);
    } finally {
      setBusy(false);
    }
  }

  return (
    <Modal open={open} title="Log in to the PLC" onClose={onClose}>
      <form class="form" onSubmit={submit}>
        <label>User name
          <input name="user" autocomplete="username" value={user} required autofocus
            onInput={(e) => setUser(e.currentTarget.value)} />
        </label>
        <label>Password
          <input name="password" type="password" autocomplete="current-password" value={password} required
            onInput={(e) => setPassword(e.currentTarget.value)} />
        </label>
        <ErrorNote error={error} />
        <p class="hint">Users are made on the PLC with <code>syncplc user add</code>. Viewers read, operators also write values, engineers also force values and load projects.</p>
        <div class="actions">
          <button type="button" class="btn" onClick={onClose}>Cancel</button>
          <button type="submit" class="btn primary" disabled={busy}>{busy ? 'Logging in…' : 'Log in'}</button>
        </div>
      </form>
    </Modal>
  );
}
