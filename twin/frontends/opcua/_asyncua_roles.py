"""The accounts and roles of `security`, as asyncua's user manager and permission ruleset (its public API:
`UserManager.get_user` when a session is activated, `PermissionRuleset.check_validity` before each of its
requests)."""
from __future__ import annotations

import hmac
from collections.abc import Callable
from dataclasses import dataclass

from asyncua import ua
from asyncua.crypto.permission_rules import USER_TYPES, PermissionRuleset, User, UserRole
from asyncua.server.user_managers import UserManager

from .security import Account, is_reader


@dataclass(eq=False)
class SessionUser(User):
    """The user of one activated session (a new object per activation, so it also names the session):
    `read_only` for a read-only account; `peer` and `source` once the session is known (`sessions`)."""

    read_only: bool = False
    peer: str = ""
    source: str = ""


class Accounts(UserManager):
    """Anonymous sessions (asyncua's User role) when no account is configured; otherwise the configured accounts
    only: read-write accounts in the User role, read-only accounts in the Anonymous role."""

    def __init__(self, accounts: tuple[Account, ...]):
        self.accounts = {a.name: a for a in accounts}

    def get_user(self, iserver, username=None, password=None, certificate=None) -> User | None:
        if not self.accounts:
            return SessionUser(role=UserRole.User)
        account = self.accounts.get(username or "")
        if account is None or not hmac.compare_digest((password or "").encode(), account.password.encode()):
            return None
        # a read-only account's sessions get asyncua's least role, Anonymous: `Roles` lets it read, browse and
        # subscribe, nothing else (anonymous sessions, allowed only without accounts, are Users)
        return SessionUser(role=UserRole.Anonymous if account.read_only else UserRole.User, name=account.name,
                           read_only=account.read_only)


OnRequest = Callable[[User, ua.NodeId, object], None]  # (the session's user, the request's type id, its body)


class Roles(PermissionRuleset):
    """The User role may do what asyncua's users may (read, write, browse, subscribe, call); the Anonymous role (a
    read-only account) all of that but write and call. asyncua asks before every request of a session, so this
    is also where a request is reported (`on_request`: the comm-loss watchdog)."""

    _users = frozenset(ua.NodeId(t) for t in USER_TYPES)
    _changes = frozenset({ua.NodeId(ua.ObjectIds.WriteRequest_Encoding_DefaultBinary),
                          ua.NodeId(ua.ObjectIds.CallRequest_Encoding_DefaultBinary)})

    def __init__(self, on_request: OnRequest | None = None):
        self.on_request = on_request

    def check_validity(self, user, action_type_id, body) -> bool:
        if self.on_request is not None and isinstance(user, SessionUser):
            self.on_request(user, action_type_id, body)
        if action_type_id not in self._users:
            return user is not None and user.role == UserRole.Admin
        if is_reader(user):
            return action_type_id not in self._changes
        return True

