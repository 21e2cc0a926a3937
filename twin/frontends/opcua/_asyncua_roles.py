"""The accounts and roles of `security`, as asyncua's user manager and permission ruleset."""
from __future__ import annotations

import hmac

from asyncua import ua
from asyncua.crypto.permission_rules import USER_TYPES, PermissionRuleset, User, UserRole
from asyncua.server.user_managers import UserManager

from .security import Account, is_reader  # noqa: F401 (Account: the type of accounts)


class Accounts(UserManager):
    """Anonymous sessions (asyncua's User role) when no account is configured; otherwise the configured accounts
    only: read-write accounts in the User role, read-only accounts in the Anonymous role."""

    def __init__(self, accounts: tuple[Account, ...]):
        self.accounts = {a.name: a for a in accounts}

    def get_user(self, iserver, username=None, password=None, certificate=None) -> User | None:
        if not self.accounts:
            return User(role=UserRole.User)
        account = self.accounts.get(username or "")
        if account is None or not hmac.compare_digest((password or "").encode(), account.password.encode()):
            return None
        # a read-only account's sessions get asyncua's least role, Anonymous: `Roles` lets it read, browse and
        # subscribe, nothing else (anonymous sessions, allowed only without accounts, are Users)
        return User(role=UserRole.Anonymous if account.read_only else UserRole.User, name=account.name)


class Roles(PermissionRuleset):
    """The User role may do what asyncua's users may (read, write, browse, subscribe, call); the Anonymous role (a
    read-only account) all of that but write and call."""

    _users = frozenset(ua.NodeId(t) for t in USER_TYPES)
    _changes = frozenset({ua.NodeId(ua.ObjectIds.WriteRequest_Encoding_DefaultBinary),
                          ua.NodeId(ua.ObjectIds.CallRequest_Encoding_DefaultBinary)})

    def check_validity(self, user, action_type_id, body) -> bool:
        if action_type_id not in self._users:
            return user is not None and user.role == UserRole.Admin
        if is_reader(user):
            return action_type_id not in self._changes
        return True
