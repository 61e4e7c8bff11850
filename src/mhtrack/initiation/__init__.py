"""initiation"""
